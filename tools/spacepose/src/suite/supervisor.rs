//! The supervisor: the process that runs a suite (`spacepose up` leaves one
//! running, `spacepose demo` is one) calls [`Supervisor::step`] every few
//! milliseconds. It
//! - detects dead services (process exit, reaped at once; dead iceoryx2
//!   nodes of the prefix, whose stale resources it removes) and hung ones
//!   (no heartbeat within `hang_timeout`, e.g. SIGSTOP: it kills them);
//! - restarts them by the restart policy (backoff, window, see [`super::restart`]);
//! - runs estimator swaps ([`super::swap`]);
//! - keeps `state.json` current: role, status, restarts and last frame of
//!   every instance, for `spacepose status`.

use super::health::HealthWatch;
use super::launch::RunningSuite;
use super::plan::{Plan, PlannedInstance};
use super::restart::RestartHistory;
use super::swap::{SwapJob, SwapReport};
use anyhow::Result;
use iceoryx2::node::NodeView;
use iceoryx2::prelude::*;
use spacepose_bus::{Bus, Publisher, Subscriber, cleanup_dead_nodes, iceoryx2_config};
use spacepose_messages::ServiceKind;
use spacepose_messages::{Command, Names, PoseEstimate};
use std::collections::BTreeMap;
use std::io::Write;
use std::time::{Duration, Instant};

pub use super::plan::configured_primary;

/// How often dead iceoryx2 nodes are looked for.
const DEAD_NODE_SCAN: Duration = Duration::from_millis(250);
/// How often `state.json` is rewritten when nothing changed.
const STATE_SAVE: Duration = Duration::from_millis(500);

/// A detected fault and what the supervisor did about it.
#[derive(Debug, Clone)]
pub struct Fault {
    /// Instance.
    pub instance: String,
    /// How it was detected: `exit: <status>`, `hung`, `dead iceoryx2 node`.
    pub cause: String,
    /// When it was detected.
    pub detected_at: Instant,
    /// When the replacement process was started.
    pub restarted_at: Option<Instant>,
    /// When the replacement sent its first heartbeat.
    pub healthy_at: Option<Instant>,
    /// `restart`, `leave` (policy) or `give up` (too many restarts).
    pub decision: String,
}

#[derive(Debug, Default)]
struct Record {
    history: RestartHistory,
    started_at: Option<Instant>,
    /// A heartbeat came from the current process.
    healthy: bool,
    restart_at: Option<Instant>,
    /// Being stopped on purpose (swapped out): its exit is no fault.
    retiring: bool,
    /// Fault waiting for the replacement's first heartbeat.
    open_fault: Option<usize>,
    /// Killed by the supervisor for hanging (its exit is part of that fault).
    killed_for_hang: bool,
    /// Left down (`leave` or `give up`): its exit has been handled, and the
    /// reaped status that `try_exit` keeps returning is not a new fault.
    down: bool,
}

/// Supervises a started suite.
pub struct Supervisor {
    /// The plan (instances updated by swaps).
    pub plan: Plan,
    /// The processes.
    pub suite: RunningSuite,
    /// Heartbeats.
    pub watch: HealthWatch,
    poses: Subscriber<PoseEstimate>,
    commands: Publisher<Command>,
    records: BTreeMap<String, Record>,
    /// Every fault detected so far.
    pub faults: Vec<Fault>,
    /// Dead iceoryx2 nodes whose resources were removed.
    pub cleaned_nodes: usize,
    /// The filter's primary tracker.
    pub primary: Option<String>,
    swap: Option<SwapJob>,
    /// Finished swaps.
    pub swaps: Vec<SwapReport>,
    swap_count: u32,
    last_scan: Instant,
    last_save: Instant,
    _bus: Bus,
}

impl std::fmt::Debug for Supervisor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Supervisor")
            .field("prefix", &self.plan.names.prefix())
            .field("faults", &self.faults.len())
            .finish()
    }
}

impl Supervisor {
    /// Takes over a started suite; `bus` is this process's node.
    pub fn new(plan: Plan, bus: Bus, watch: HealthWatch, mut suite: RunningSuite) -> Result<Self> {
        let names: &Names = &plan.names;
        let poses = bus.subscriber(&names.pose())?;
        let commands = bus.publisher(&names.command())?;
        let now = Instant::now();
        let records = suite
            .state
            .instances
            .iter()
            .map(|i| {
                let r = Record {
                    started_at: Some(now),
                    healthy: true,
                    ..Record::default()
                };
                (i.name.clone(), r)
            })
            .collect();
        let primary = configured_primary(&plan);
        suite.state.supervisor_pid = Some(std::process::id());
        suite.state.primary.clone_from(&primary);
        let mut s = Self {
            plan,
            suite,
            watch,
            poses,
            commands,
            records,
            faults: Vec::new(),
            cleaned_nodes: 0,
            primary,
            swap: None,
            swaps: Vec::new(),
            swap_count: 0,
            last_scan: now,
            last_save: now,
            _bus: bus,
        };
        s.refresh_state();
        s.suite.state.save()?;
        Ok(s)
    }

    /// One round: heartbeats, exits, hangs, restarts, dead nodes, swap, state.
    /// Returns the poses received (for a caller that scores them).
    pub fn step(&mut self, out: &mut dyn Write) -> Result<Vec<PoseEstimate>> {
        let now = Instant::now();
        self.watch.drain()?;
        let mut poses = Vec::new();
        while let Some(p) = self.poses.try_recv()? {
            poses.push(p);
        }
        self.note_heartbeats();
        self.check_exits(now, out)?;
        self.check_hangs(now, out);
        self.run_restarts(out)?;
        if now.duration_since(self.last_scan) >= DEAD_NODE_SCAN {
            self.last_scan = now;
            self.scan_dead_nodes(out)?;
        }
        self.step_swap(&poses, out)?;
        if now.duration_since(self.last_save) >= STATE_SAVE {
            self.save_state()?;
        }
        Ok(poses)
    }

    /// Writes `state.json` now.
    pub fn save_state(&mut self) -> Result<()> {
        self.refresh_state();
        self.suite.state.save()?;
        self.last_save = Instant::now();
        Ok(())
    }

    fn note_heartbeats(&mut self) {
        for inst in &self.suite.state.instances {
            let Some(r) = self.records.get_mut(&inst.name) else {
                continue;
            };
            let from_current = self
                .watch
                .get(&inst.name)
                .is_some_and(|h| h.pid == inst.pid);
            if from_current && !r.healthy {
                r.healthy = true;
                if let Some(f) = r.open_fault.take()
                    && let Some(fault) = self.faults.get_mut(f)
                {
                    fault.healthy_at = self.watch.received_at(&inst.name);
                }
            }
        }
    }

    fn clean_dead_nodes(&self) -> usize {
        iceoryx2_config(&self.plan.names)
            .ok()
            .and_then(|c| cleanup_dead_nodes(&c).ok())
            .unwrap_or(0)
    }

    /// Dead iceoryx2 nodes of the prefix: a service that died without our
    /// noticing its exit (not our child). Their resources are removed.
    fn scan_dead_nodes(&mut self, out: &mut dyn Write) -> Result<()> {
        let config = iceoryx2_config(&self.plan.names)?;
        let mut dead = Vec::new();
        let _ = Node::<ipc::Service>::list(&config, |state| {
            if let NodeState::Dead(view) = state {
                dead.push(
                    view.details()
                        .as_ref()
                        .map(|d| d.name().to_string())
                        .unwrap_or_default(),
                );
            }
            CallbackProgression::Continue
        });
        if dead.is_empty() {
            return Ok(());
        }
        let cleaned = self.clean_dead_nodes();
        self.cleaned_nodes += cleaned;
        writeln!(
            out,
            "supervisor: removed the resources of {cleaned} dead iceoryx2 node(s): {}",
            dead.join(", ")
        )?;
        Ok(())
    }

    /// The planned instance `name` (for restarts).
    pub fn planned(&self, name: &str) -> Option<&PlannedInstance> {
        self.plan.instances.iter().find(|i| i.name == name)
    }

    fn refresh_state(&mut self) {
        let primary = self.primary.clone();
        let trackers = self
            .suite
            .state
            .instances
            .iter()
            .filter(|i| i.kind == ServiceKind::Tracker)
            .count();
        for inst in &mut self.suite.state.instances {
            inst.role = match (&primary, inst.kind) {
                (Some(p), ServiceKind::Tracker) if *p == inst.name => "primary".into(),
                (Some(_), ServiceKind::Tracker) => "standby".into(),
                (None, ServiceKind::Tracker) if trackers > 1 => "first-arrival".into(),
                _ => String::new(),
            };
            if let Some(h) = self.watch.get(&inst.name).filter(|h| h.pid == inst.pid) {
                inst.last_frame = Some(h.counters.last_frame);
            }
            let r = self.records.get(&inst.name);
            if r.is_some_and(|r| r.retiring) {
                inst.status = "stopping".into();
            } else if r.is_some_and(|r| r.killed_for_hang) {
                inst.status = "hung".into();
            } else if r.is_some_and(|r| r.restart_at.is_none() && r.healthy) {
                inst.status = "running".into();
            }
        }
        self.suite.state.primary = primary;
    }

    /// Stops everything (see [`RunningSuite::stop`]).
    pub fn stop(self, out: &mut dyn Write) -> Result<()> {
        let Supervisor {
            suite,
            watch,
            poses,
            commands,
            _bus,
            ..
        } = self;
        drop((watch, poses, commands, _bus));
        suite.stop(out)
    }
}

mod faults;
mod swaps;

#[cfg(test)]
#[path = "supervisor_tests.rs"]
mod tests;
