//! The recorder node: every input into the MCAP file, closed on the way out.

use crate::config::RecorderConfig;
use crate::run_info::{free_path, record_descriptor, target_mesh};
use anyhow::Context;
use spacepose_foxglove::Recorder;
use spacepose_messages::{Cloud, Message, ServiceKind};
use spacepose_runtime::{Ctx, Node, NodeInfo};
use std::collections::BTreeMap;

/// Records what it receives; `None` once the file is closed.
pub struct RecorderNode {
    recorder: Option<Recorder>,
}

impl Node for RecorderNode {
    const KIND: ServiceKind = ServiceKind::Recorder;
    type Config = RecorderConfig;

    fn new(config: RecorderConfig, info: &NodeInfo) -> anyhow::Result<Self> {
        let path = free_path(&config.file);
        if path != config.file {
            tracing::warn!(
                "{} exists (a restart?): recording into {}",
                config.file.display(),
                path.display()
            );
        }
        // Linux niceness is per thread: this one runs the node's loop.
        if let Err(e) = rustix::process::setpriority_process(None, config.nice) {
            tracing::warn!("nice {}: {e}", config.nice);
        }
        let mut recorder = Recorder::create(&path, config.options())?;
        if !config.target.is_empty() {
            recorder.set_target(target_mesh(&config.target, config.target_scale)?);
        }
        let run = BTreeMap::from([
            ("prefix".to_string(), info.names.prefix().to_string()),
            ("instance".to_string(), info.instance.as_str().to_string()),
            ("log_time".to_string(), "sensor clock (ns)".to_string()),
            ("target".to_string(), config.target.clone()),
        ]);
        recorder.metadata("spacepose.run", run)?;
        if !config.descriptor.is_empty() {
            record_descriptor(&recorder, &config.descriptor)?;
        }
        tracing::info!("recording to {}", path.display());
        Ok(Self {
            recorder: Some(recorder),
        })
    }

    fn on_message(&mut self, msg: &Message, ctx: &mut Ctx<'_>) {
        let Some(rec) = self.recorder.as_mut() else {
            return;
        };
        ctx.counters.frames_in += 1;
        match rec.message(msg) {
            Ok(()) => ctx.counters.frames_out += 1,
            Err(e) => {
                ctx.counters.rejected_wire += 1;
                tracing::warn!("{:?} not recorded: {e}", msg.topic());
            }
        }
    }

    fn on_cloud(&mut self, cloud: Cloud<'_>, ctx: &mut Ctx<'_>) {
        let Some(rec) = self.recorder.as_mut() else {
            return;
        };
        ctx.counters.frames_in += 1;
        ctx.counters.last_frame = cloud.header.sequence;
        match rec.cloud(cloud) {
            Ok(true) => ctx.counters.frames_out += 1,
            Ok(false) => {}
            Err(e) => {
                ctx.counters.errors += 1;
                tracing::warn!("cloud {} not recorded: {e}", cloud.header.sequence);
            }
        }
    }

    fn stop(&mut self, ctx: &mut Ctx<'_>) {
        let Some(rec) = self.recorder.take() else {
            return;
        };
        match rec.close().context("closing the recording") {
            Ok(stats) => tracing::info!(
                "recording closed: {} clouds ({} skipped), {} messages",
                stats.clouds,
                stats.clouds_skipped,
                stats.messages
            ),
            Err(e) => {
                ctx.counters.errors += 1;
                tracing::error!("{e:#}");
            }
        }
    }
}

#[cfg(test)]
#[path = "node_tests.rs"]
mod tests;
