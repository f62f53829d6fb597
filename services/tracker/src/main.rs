//! `spacepose-tracker`: follows the target frame after frame.
//!
//! Wakes on cropped clouds, filter states, acquisition results and commands;
//! publishes exactly one `PoseEstimate` per cloud (a `lost` one before
//! initialisation and for bad input). Logic: [`TrackerNode`].

use anyhow::Context;
use clap::Parser;
use serde::Deserialize;
use spacepose_bus::{Bus, CloudSubscriber, Publisher, Subscriber, WakeReason};
use spacepose_messages::{
    AcquisitionResult, Command, FilterState, Name, Names, PoseEstimate, ServiceState,
};
use spacepose_service_kit::{
    Counters, HealthReporter, ServiceArgs, ServiceConfig, init_logging, load_config, shutdown_flag,
};
use spacepose_tracker::{FrameResult, InputIssue, TrackError, TrackerNode, TrackerServiceConfig};
use std::process::ExitCode;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

const SERVICE: &str = "tracker";

/// The service configuration as a TOML file ([`TrackerServiceConfig`]).
#[derive(Debug, Default, Deserialize)]
#[serde(transparent)]
struct Config(TrackerServiceConfig);

impl ServiceConfig for Config {
    fn validate(&self) -> Result<(), String> {
        self.0.validate().map_err(|e| e.to_string())
    }
}

fn main() -> ExitCode {
    match run(ServiceArgs::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!("{e:#}");
            eprintln!("spacepose-tracker: {e:#}");
            ExitCode::FAILURE
        }
    }
}

struct Ports {
    clouds: CloudSubscriber,
    states: Subscriber<FilterState>,
    acquisitions: Subscriber<AcquisitionResult>,
    commands: Subscriber<Command>,
    poses: Publisher<PoseEstimate>,
}

fn run(args: ServiceArgs) -> anyhow::Result<()> {
    init_logging(SERVICE);
    let Config(config) = load_config(args.config.as_deref())?;
    let names = Names::new(&args.prefix).context("deployment prefix")?;
    let instance = args
        .instance
        .clone()
        .or_else(|| config.instance.clone())
        .unwrap_or_else(|| SERVICE.to_string());
    let instance_name = Name::new(&instance).context("instance name")?;
    let shutdown = shutdown_flag();

    let started = Instant::now();
    let (model, source) = config.build_model()?;
    tracing::info!(
        target = config.target,
        ?source,
        ms = started.elapsed().as_millis() as u64,
        "model ready"
    );
    let mut node = TrackerNode::new(
        config.tracker.clone(),
        model,
        instance_name,
        config.max_points,
    )?;

    let bus = Bus::open(&names, &instance).context("opening the bus")?;
    let ports = Ports {
        clouds: bus.cloud_subscriber(&names.cloud())?,
        states: bus.subscriber(&names.filter_state())?,
        acquisitions: bus.subscriber(&names.acquisition())?,
        commands: bus.subscriber(&names.command())?,
        poses: bus.publisher(&names.pose())?,
    };
    let heartbeat = Duration::from_millis(args.heartbeat_ms.max(1));
    let mut health = HealthReporter::new(&bus, &names, SERVICE, &instance, heartbeat)?;
    let mut waiter = bus.waitset()?;
    waiter.attach(&ports.clouds)?;
    waiter.attach(&ports.states)?;
    waiter.attach(&ports.acquisitions)?;
    waiter.attach(&ports.commands)?;
    let mut counters = Counters::default();
    tracing::info!(prefix = names.prefix(), instance, mode = %node.tracker().mode(), "tracker service running");
    while !shutdown.load(Ordering::Relaxed) {
        if waiter.wait(heartbeat)? == WakeReason::TerminationRequested {
            break;
        }
        drain_control(&ports, &mut node, &mut counters);
        drain_clouds(&ports, &mut node, &mut counters);
        let state = if node.is_tracking() {
            ServiceState::Running
        } else {
            ServiceState::Degraded
        };
        health.tick(&counters, state as u8)?;
    }
    tracing::info!("tracker service stopping");
    health.send(&counters, ServiceState::Stopping as u8)?;
    Ok(())
}

/// Drains `sub`, handing every message to `handle`; errors are counted.
fn drain<T: spacepose_bus::Msg>(
    sub: &Subscriber<T>,
    counters: &mut Counters,
    mut handle: impl FnMut(&T) -> Result<(), TrackError>,
) {
    loop {
        match sub.try_recv() {
            Ok(Some(m)) => {
                if let Err(e) = handle(&m) {
                    counters.rejected_wire += 1;
                    tracing::warn!(service = sub.service(), "message refused: {e}");
                }
            }
            Ok(None) => return,
            Err(e) => {
                counters.errors += 1;
                tracing::warn!("receiving: {e}");
                return;
            }
        }
    }
}

/// Commands, acquisitions and filter states, in that order (each applies
/// before the clouds that arrived after it).
fn drain_control(ports: &Ports, node: &mut TrackerNode, counters: &mut Counters) {
    drain(&ports.commands, counters, |c| {
        let outcome = node.on_command(c)?;
        tracing::info!(issued_by = %c.issued_by, ?outcome, "command");
        Ok(())
    });
    drain(&ports.acquisitions, counters, |a| {
        if node.on_acquisition(a)? {
            tracing::info!(
                sequence = a.sequence,
                t_s = a.t_s,
                method = a.method,
                "acquisition: (re)initialising at the next frame"
            );
        }
        Ok(())
    });
    drain(&ports.states, counters, |s| node.on_filter_state(s));
}

fn drain_clouds(ports: &Ports, node: &mut TrackerNode, counters: &mut Counters) {
    loop {
        let sample = match ports.clouds.try_recv() {
            Ok(Some(s)) => s,
            Ok(None) => return,
            Err(e) => {
                counters.errors += 1;
                tracing::warn!("receiving a cloud: {e}");
                return;
            }
        };
        // Control messages sent before this cloud apply to it.
        drain_control(ports, node, counters);
        counters.frames_in += 1;
        counters.last_frame = sample.header().sequence;
        let result = node.on_cloud(sample.header(), sample.points());
        drop(sample);
        count(&result, counters);
        match ports.poses.send(&result.estimate) {
            Ok(()) => counters.frames_out += 1,
            Err(e) => {
                counters.errors += 1;
                tracing::warn!("publishing the pose: {e}");
            }
        }
    }
}

fn count(r: &FrameResult, counters: &mut Counters) {
    let seq = r.estimate.sequence;
    match r.issue {
        Some(InputIssue::Oversized { .. }) => counters.rejected_oversized += 1,
        Some(InputIssue::NonFinite { .. }) => counters.rejected_non_finite += 1,
        None => {}
    }
    if let Some(issue) = r.issue {
        tracing::warn!(sequence = seq, ?issue, "bad input frame");
    }
    if let Some(e) = &r.error {
        counters.errors += 1;
        tracing::warn!(sequence = seq, "frame not tracked: {e}");
    }
    if !r.reason.is_empty() {
        tracing::debug!(
            sequence = seq,
            status = r.estimate.status,
            reason = r.reason,
            "frame"
        );
    }
}
