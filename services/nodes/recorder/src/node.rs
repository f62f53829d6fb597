//! The recorder node: every input into the MCAP file (closed on the way
//! out) and onto the live view.

use crate::config::RecorderConfig;
use crate::live_config::LiveConfig;
use crate::run_info::{free_path, record_descriptor, target_mesh};
use anyhow::Context;
use spacepose_foxglove::{LiveView, Recorder, TargetMesh};
use spacepose_messages::{Cloud, Message, ServiceKind};
use spacepose_runtime::{Ctx, Node, NodeInfo};
use std::collections::BTreeMap;
use std::path::Path;

/// Records what it receives and streams it live; `None` once stopped.
pub struct RecorderNode {
    recorder: Option<Recorder>,
    live: Option<LiveView>,
}

/// Opens the MCAP file `file` (or the next free part beside it) and
/// records the run's metadata, the descriptor and the target model.
fn open_recording(
    file: &Path,
    config: &RecorderConfig,
    info: &NodeInfo,
    mesh: Option<&TargetMesh>,
) -> anyhow::Result<Recorder> {
    let path = free_path(file);
    if path != file {
        tracing::warn!(
            "{} exists (a restart?): recording into {}",
            file.display(),
            path.display()
        );
    }
    let mut recorder = Recorder::create(&path, config.options())?;
    if let Some(mesh) = mesh {
        recorder.set_target(mesh.clone());
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
    Ok(recorder)
}

/// Starts the live view (the access rule is checked by the configuration;
/// a non-loopback address it allowed is warned about).
fn start_live(live: &LiveConfig, mesh: Option<&TargetMesh>) -> anyhow::Result<LiveView> {
    let addr = live.listen_addr().map_err(anyhow::Error::msg)?;
    if live.is_non_loopback() {
        tracing::warn!(
            "live view on {addr}, beyond loopback (allow_non_loopback): the Foxglove \
             WebSocket protocol has no authentication, anyone reaching the port sees the run"
        );
    }
    let mut view = LiveView::start(addr, live.options())?;
    if let Some(mesh) = mesh {
        view.set_target(mesh.clone());
    }
    tracing::info!("live view on ws://{}", view.local_addr());
    Ok(view)
}

impl Node for RecorderNode {
    const KIND: ServiceKind = ServiceKind::Recorder;
    type Config = RecorderConfig;

    fn new(config: RecorderConfig, info: &NodeInfo) -> anyhow::Result<Self> {
        // Linux niceness is per thread: this one runs the node's loop, and
        // the live view's server threads inherit it.
        if let Err(e) = rustix::process::setpriority_process(None, config.nice) {
            tracing::warn!("nice {}: {e}", config.nice);
        }
        let mesh = if config.target.is_empty() {
            None
        } else {
            Some(target_mesh(&config.target, config.target_scale)?)
        };
        let recorder = config
            .file
            .as_deref()
            .map(|file| open_recording(file, &config, info, mesh.as_ref()))
            .transpose()?;
        let live = config
            .live
            .as_ref()
            .map(|live| start_live(live, mesh.as_ref()))
            .transpose()?;
        Ok(Self { recorder, live })
    }

    fn on_message(&mut self, msg: &Message, ctx: &mut Ctx<'_>) {
        if self.recorder.is_none() && self.live.is_none() {
            return;
        }
        ctx.counters.frames_in += 1;
        let recorded = self.recorder.as_mut().map(|r| r.message(msg));
        let sent = self.live.as_mut().map(|l| l.message(msg));
        // Both convert the same message the same way: one verdict.
        match recorded.or(sent) {
            Some(Ok(())) => ctx.counters.frames_out += 1,
            Some(Err(e)) => {
                ctx.counters.rejected_wire += 1;
                tracing::warn!("{:?} not recorded: {e}", msg.topic());
            }
            None => {}
        }
    }

    fn on_cloud(&mut self, cloud: Cloud<'_>, ctx: &mut Ctx<'_>) {
        if self.recorder.is_none() && self.live.is_none() {
            return;
        }
        ctx.counters.frames_in += 1;
        ctx.counters.last_frame = cloud.header.sequence;
        let recorded = self.recorder.as_mut().map(|r| r.cloud(cloud));
        let sent = self.live.as_mut().map(|l| l.cloud(cloud));
        let mut out = false;
        for result in [recorded, sent].into_iter().flatten() {
            match result {
                Ok(kept) => out |= kept,
                Err(e) => {
                    ctx.counters.errors += 1;
                    tracing::warn!("cloud {} not recorded: {e}", cloud.header.sequence);
                }
            }
        }
        if out {
            ctx.counters.frames_out += 1;
        }
    }

    fn stop(&mut self, ctx: &mut Ctx<'_>) {
        if let Some(live) = self.live.take() {
            let s = live.stop();
            tracing::info!(
                "live view stopped: {} clouds ({} skipped, {} points), {} messages",
                s.clouds,
                s.clouds_skipped,
                s.points,
                s.messages
            );
        }
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
