//! `spacepose-filter`: the authority on the relative motion.
//!
//! Subscribes to the trackers' `PoseEstimate`s, to `AcquisitionResult`s and
//! to commands, initialises on an accepted acquisition, fuses one estimate
//! per frame (the primary tracker's, or a standby's when the primary's is
//! missing at the frame deadline, late or unusable) and publishes the
//! `FilterState` after every change and every `state_period_ms` (heartbeat
//! for late joiners). A `swap` command names the new primary (applied at
//! the next undecided frame). Failover is sticky: a standby that replaced
//! a missing primary on `promote_after_misses` consecutive frames becomes
//! the acting primary, and the preferred one takes the role back after
//! `revert_after_frames` good frames (logged). Logic: [`FilterNode`].

use anyhow::Context;
use clap::Parser;
use serde::Deserialize;
use spacepose_bus::{Bus, Publisher, Subscriber, WakeReason};
use spacepose_filter::snapshot::{load_snapshot, save_snapshot};
use spacepose_filter::{
    EstimateOutcome, FilterError, FilterNode, FilterServiceConfig, Fusion, Reason,
};
use spacepose_messages::{
    AcquisitionResult, Command, CommandKind, FilterState, Names, PoseEstimate, ServiceState,
    realtime_ns,
};
use spacepose_service_kit::{
    Counters, HealthReporter, ServiceArgs, ServiceConfig, init_logging, load_config, shutdown_flag,
};
use std::process::ExitCode;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

const SERVICE: &str = "filter";

/// The service configuration as a TOML file ([`FilterServiceConfig`]).
#[derive(Debug, Default, Deserialize)]
#[serde(transparent)]
struct Config(FilterServiceConfig);

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
            eprintln!("spacepose-filter: {e:#}");
            ExitCode::FAILURE
        }
    }
}

struct Ports {
    estimates: Subscriber<PoseEstimate>,
    acquisitions: Subscriber<AcquisitionResult>,
    commands: Subscriber<Command>,
    states: Publisher<FilterState>,
}

fn run(args: ServiceArgs) -> anyhow::Result<()> {
    init_logging(SERVICE);
    let Config(config) = load_config(args.config.as_deref())?;
    let names = Names::new(&args.prefix).context("deployment prefix")?;
    let instance = args.instance_or(SERVICE);
    let shutdown = shutdown_flag();
    let bus = Bus::open(&names, &instance).context("opening the bus")?;
    let ports = Ports {
        estimates: bus.subscriber(&names.pose())?,
        acquisitions: bus.subscriber(&names.acquisition())?,
        commands: bus.subscriber(&names.command())?,
        states: bus.publisher(&names.filter_state())?,
    };
    let heartbeat = Duration::from_millis(args.heartbeat_ms.max(1));
    let mut health = HealthReporter::new(&bus, &names, SERVICE, &instance, heartbeat)?;
    let mut waiter = bus.waitset()?;
    waiter.attach(&ports.estimates)?;
    waiter.attach(&ports.acquisitions)?;
    waiter.attach(&ports.commands)?;
    let mut node = FilterNode::new(&config)?;
    let mut counters = Counters::default();
    let resumed = resume(&config, &mut node, &mut counters);
    let state_period =
        (config.state_period_ms > 0).then(|| Duration::from_millis(config.state_period_ms));
    let mut last_state = Instant::now();
    if resumed {
        publish(&ports, &node, &mut counters);
    }
    tracing::info!(prefix = names.prefix(), instance, primary = ?node.primary(), "filter service running");
    while !shutdown.load(Ordering::Relaxed) {
        let mut timeout = state_period.map_or(heartbeat, |p| p.min(heartbeat));
        if let Some(deadline_ns) = node.next_deadline_ns() {
            let left_ns = deadline_ns.saturating_sub(realtime_ns()).max(0) as u64;
            // Wake just after the deadline, not before it.
            timeout = timeout.min(Duration::from_nanos(left_ns) + Duration::from_micros(200));
        }
        if waiter.wait(timeout)? == WakeReason::TerminationRequested {
            break;
        }
        let mut changed = drain_commands(&ports, &mut node, &mut counters);
        changed |= drain_acquisitions(&ports, &mut node, &mut counters);
        changed |= drain_estimates(&ports, &mut node, &mut counters);
        changed |= report(node.poll(realtime_ns()), &mut counters);
        for c in node.take_role_changes() {
            tracing::warn!(from = c.from, to = c.to, cause = ?c.cause, from_frame = c.from_frame, "acting primary changed");
        }
        if changed || state_period.is_some_and(|p| last_state.elapsed() >= p) {
            publish(&ports, &node, &mut counters);
            last_state = Instant::now();
        }
        if changed {
            persist(&config, &node, &mut counters);
        }
        let state = if node.filter().is_initialized() {
            ServiceState::Running
        } else {
            ServiceState::Degraded
        };
        health.tick(&counters, state as u8)?;
    }
    tracing::info!("filter service stopping");
    health.send(&counters, ServiceState::Stopping as u8)?;
    Ok(())
}

/// Restores the state of a previous filter process from a fresh snapshot
/// (`snapshot_file`); returns whether it did. A bad snapshot is logged,
/// counted and ignored.
fn resume(config: &FilterServiceConfig, node: &mut FilterNode, counters: &mut Counters) -> bool {
    let Some(path) = &config.snapshot_file else {
        return false;
    };
    let max_age = Duration::from_secs_f64(config.snapshot_max_age_s);
    let restored = load_snapshot(path, max_age).and_then(|s| match s {
        Some(s) => node.restore(&s).map(|ok| ok.then_some(s.t_s)),
        None => Ok(None),
    });
    match restored {
        Ok(Some(t_s)) => {
            tracing::info!(path = %path.display(), t_s, "resumed from the previous filter's snapshot");
            true
        }
        Ok(None) => false,
        Err(e) => {
            counters.errors += 1;
            tracing::warn!("snapshot ignored: {e}");
            false
        }
    }
}

/// Writes the state to `snapshot_file` (if configured).
fn persist(config: &FilterServiceConfig, node: &FilterNode, counters: &mut Counters) {
    if let Some(path) = &config.snapshot_file
        && node.filter().is_initialized()
        && let Err(e) = save_snapshot(path, &node.state())
    {
        counters.errors += 1;
        tracing::warn!("{e}");
    }
}

fn publish(ports: &Ports, node: &FilterNode, counters: &mut Counters) {
    match ports.states.send(&node.state()) {
        Ok(()) => counters.frames_out += 1,
        Err(e) => {
            counters.errors += 1;
            tracing::warn!("publishing the filter state: {e}");
        }
    }
}

/// Returns whether an acquisition (re)initialised the filter.
fn drain_acquisitions(ports: &Ports, node: &mut FilterNode, counters: &mut Counters) -> bool {
    let mut changed = false;
    loop {
        let a = match ports.acquisitions.try_recv() {
            Ok(Some(a)) => a,
            Ok(None) => return changed,
            Err(e) => {
                counters.errors += 1;
                tracing::warn!("receiving an acquisition: {e}");
                return changed;
            }
        };
        match node.on_acquisition(&a) {
            Ok(true) => {
                tracing::info!(
                    sequence = a.sequence,
                    t_s = a.t_s,
                    "initialised by an acquisition"
                );
                changed = true;
            }
            Ok(false) => tracing::info!(sequence = a.sequence, "failed acquisition ignored"),
            Err(e) => {
                counters.rejected_wire += 1;
                tracing::warn!("acquisition refused: {e}");
            }
        }
    }
}

/// Applies swap commands (the target instance becomes the primary); other
/// commands are for the trackers. Returns whether a fusion changed the state.
fn drain_commands(ports: &Ports, node: &mut FilterNode, counters: &mut Counters) -> bool {
    let mut changed = false;
    loop {
        let c = match ports.commands.try_recv() {
            Ok(Some(c)) => c,
            Ok(None) => return changed,
            Err(e) => {
                counters.errors += 1;
                tracing::warn!("receiving a command: {e}");
                return changed;
            }
        };
        match CommandKind::from_u8(c.kind) {
            Ok(CommandKind::Swap) if !c.target_instance.is_empty() => {
                let new = c.target_instance.as_str().to_string();
                tracing::info!(
                    issued_by = %c.issued_by,
                    old = ?node.primary(),
                    new,
                    "swap: new primary from the next frame"
                );
                changed |= report(node.set_primary(&new), counters);
            }
            Ok(CommandKind::Swap) => {
                counters.rejected_wire += 1;
                tracing::warn!(issued_by = %c.issued_by, "swap command without a target instance refused");
            }
            Ok(_) => {}
            Err(e) => {
                counters.rejected_wire += 1;
                tracing::warn!("command refused: {e}");
            }
        }
    }
}

/// Logs the selector's decisions; returns whether one changed the state.
fn report(fusions: Vec<Fusion>, counters: &mut Counters) -> bool {
    let mut changed = false;
    for f in fusions {
        changed |= f.changed_state();
        if !matches!(f.reason, Reason::Primary | Reason::FirstArrival) {
            tracing::info!(sequence = f.sequence, instance = f.instance, reason = ?f.reason, "standby estimate taken");
        }
        match &f.outcome {
            Ok(EstimateOutcome::InitializedFromEstimate) => {
                tracing::info!(
                    sequence = f.sequence,
                    instance = f.instance,
                    "initialised from a tracking estimate"
                );
            }
            Ok(o) if !o.changed_state() => {
                tracing::debug!(sequence = f.sequence, outcome = ?o, "estimate not fused");
            }
            Ok(_) => {}
            Err(err) => {
                counters.errors += 1;
                tracing::warn!(sequence = f.sequence, "filter update failed: {err}");
            }
        }
    }
    changed
}

/// Returns whether an estimate changed the state.
fn drain_estimates(ports: &Ports, node: &mut FilterNode, counters: &mut Counters) -> bool {
    let mut changed = false;
    loop {
        let e = match ports.estimates.try_recv() {
            Ok(Some(e)) => e,
            Ok(None) => return changed,
            Err(err) => {
                counters.errors += 1;
                tracing::warn!("receiving an estimate: {err}");
                return changed;
            }
        };
        counters.frames_in += 1;
        counters.last_frame = e.sequence;
        match node.on_estimate(&e, realtime_ns()) {
            Ok((_, fusions)) => changed |= report(fusions, counters),
            Err(err @ FilterError::InvalidMessage { .. }) => {
                counters.rejected_non_finite += 1;
                tracing::warn!(sequence = e.sequence, "estimate refused: {err}");
            }
            Err(err) => {
                counters.errors += 1;
                tracing::warn!(sequence = e.sequence, "filter update failed: {err}");
            }
        }
    }
}
