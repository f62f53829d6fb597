//! What the supervisor does when an instance exits or hangs: the fault,
//! the restart policy's decision, and the restarts it schedules.

use super::{Fault, Record, Supervisor};
use crate::suite::restart::{Decision, Policy, Stop};
use anyhow::{Context, Result};
use rustix::process::Signal;
use std::io::Write;
use std::process::ExitStatus;
use std::time::Instant;

impl Record {
    /// Why the process stopped with `status`: hung when the supervisor
    /// killed it for hanging, whatever the status.
    fn stop(&self, status: ExitStatus) -> Stop {
        if self.killed_for_hang {
            Stop::Hung
        } else if status.success() {
            Stop::Clean
        } else {
            Stop::Failed(status.to_string())
        }
    }
}

/// What the supervisor reports doing: `restart in N ms`, `leave` or `give up`.
fn decision_text(decision: Decision) -> String {
    match decision {
        Decision::RestartAfter(d) => format!("restart in {} ms", d.as_millis()),
        Decision::Leave => "leave".to_string(),
        Decision::GiveUp => "give up".to_string(),
    }
}

/// Status of an instance after `decision` about its `stop`: `restarting`,
/// `exited` (left down after a clean exit) or `failed`.
fn status_after(decision: Decision, stop: &Stop) -> &'static str {
    match decision {
        Decision::RestartAfter(_) => "restarting",
        Decision::Leave if *stop == Stop::Clean => "exited",
        _ => "failed",
    }
}

impl Supervisor {
    /// Handles every instance whose process exited, unless its restart is
    /// already pending or it was left down (see [`Self::handle_exit`]).
    pub(super) fn check_exits(&mut self, now: Instant, out: &mut dyn Write) -> Result<()> {
        let names: Vec<String> = self
            .suite
            .state
            .instances
            .iter()
            .map(|i| i.name.clone())
            .collect();
        for name in names {
            let handled = self
                .records
                .get(&name)
                .is_some_and(|r| r.restart_at.is_some() || r.down);
            if handled {
                continue;
            }
            let Some(status) = self.suite.try_exit(&name) else {
                continue;
            };
            self.handle_exit(&name, status, now, out)?;
        }
        Ok(())
    }

    /// `name` exited with `status` (detected at `now`): a retiring instance
    /// is forgotten; any other exit is a fault (the one of its hang, when the
    /// supervisor killed it), its stale bus resources are removed, and its
    /// restart policy decides; the decision is reported and saved.
    fn handle_exit(
        &mut self,
        name: &str,
        status: ExitStatus,
        now: Instant,
        out: &mut dyn Write,
    ) -> Result<()> {
        let r = self.records.entry(name.to_string()).or_default();
        if r.retiring {
            return self.forget_retired(name, status, out);
        }
        let stop = r.stop(status);
        let fault = match r.open_fault.filter(|_| r.killed_for_hang) {
            Some(f) => f,
            None => self.push_exit_fault(name, status, now),
        };
        // Its node is dead now: remove its stale resources at once.
        self.cleaned_nodes += self.clean_dead_nodes();
        let decision = self.decide_restart(name, &stop, fault, now);
        self.report_decision(name, fault, decision, &stop, out)?;
        self.save_state()
    }

    /// Forgets `name`, stopped on purpose (swapped out): its exit is no fault.
    fn forget_retired(
        &mut self,
        name: &str,
        status: ExitStatus,
        out: &mut dyn Write,
    ) -> Result<()> {
        writeln!(out, "supervisor: {name} stopped ({status})")?;
        self.suite.remove(name);
        self.records.remove(name);
        Ok(())
    }

    /// Records the fault of `name` exiting with `status` at `now`; returns
    /// its index in [`Self::faults`].
    fn push_exit_fault(&mut self, name: &str, status: ExitStatus, now: Instant) -> usize {
        self.faults.push(Fault {
            instance: name.to_string(),
            cause: format!("exit: {status}"),
            detected_at: now,
            restarted_at: None,
            healthy_at: None,
            decision: String::new(),
        });
        self.faults.len() - 1
    }

    /// Decides by `name`'s restart policy (`never` when it is no longer
    /// planned) what to do after `stop`. A restart is scheduled, and `fault`
    /// stays open until the replacement's first heartbeat.
    fn decide_restart(&mut self, name: &str, stop: &Stop, fault: usize, now: Instant) -> Decision {
        let policy = self
            .planned(name)
            .map_or(Policy::Never, |p| p.restart_policy);
        let r = self.records.entry(name.to_string()).or_default();
        r.killed_for_hang = false;
        r.healthy = false;
        let decision = r.history.decide(&self.plan.restart, policy, stop, now);
        match decision {
            Decision::RestartAfter(d) => {
                r.restart_at = Some(now + d);
                r.open_fault = Some(fault);
            }
            Decision::Leave | Decision::GiveUp => r.down = true,
        }
        decision
    }

    /// Writes `decision` into fault `fault`, reports it to `out` and sets
    /// the status of `name`.
    fn report_decision(
        &mut self,
        name: &str,
        fault: usize,
        decision: Decision,
        stop: &Stop,
        out: &mut dyn Write,
    ) -> Result<()> {
        let text = decision_text(decision);
        self.faults[fault].decision = match decision {
            Decision::RestartAfter(_) => "restart".into(),
            _ => text.clone(),
        };
        writeln!(
            out,
            "supervisor: {name} {} -> {text}",
            self.faults[fault].cause
        )?;
        if let Some(i) = self.suite.index(name) {
            self.suite.state.instances[i].status = status_after(decision, stop).into();
        }
        Ok(())
    }

    /// Kills an instance that has sent no heartbeat for the plan's hang
    /// timeout, and opens the fault its exit will complete.
    pub(super) fn check_hangs(&mut self, now: Instant, out: &mut dyn Write) {
        let hang = self.plan.hang_timeout;
        let start = self.plan.health_timeout;
        for inst in &self.suite.state.instances {
            let Some(r) = self.records.get_mut(&inst.name) else {
                continue;
            };
            if r.restart_at.is_some() || r.killed_for_hang || r.retiring {
                continue;
            }
            let silent_since = if r.healthy {
                self.watch.received_at(&inst.name)
            } else {
                r.started_at.map(|t| t + start.saturating_sub(hang))
            };
            if silent_since.is_none_or(|t| now.duration_since(t) <= hang) {
                continue;
            }
            let _ = writeln!(
                out,
                "supervisor: {} sent no heartbeat for {} ms: hung, killing it",
                inst.name,
                hang.as_millis()
            );
            crate::suite::process::signal_group(inst.pid, Signal::KILL);
            r.killed_for_hang = true;
            self.faults.push(Fault {
                instance: inst.name.clone(),
                cause: "hung".into(),
                detected_at: now,
                restarted_at: None,
                healthy_at: None,
                decision: String::new(),
            });
            r.open_fault = Some(self.faults.len() - 1);
        }
    }

    /// Starts again the instances whose restart is due.
    pub(super) fn run_restarts(&mut self, out: &mut dyn Write) -> Result<()> {
        let now = Instant::now();
        let due: Vec<String> = self
            .records
            .iter()
            .filter(|(_, r)| r.restart_at.is_some_and(|t| t <= now))
            .map(|(n, _)| n.clone())
            .collect();
        for name in due {
            let Some(planned) = self.planned(&name).cloned() else {
                continue;
            };
            let pid = self.suite.spawn_instance(&self.plan, &planned)?;
            let i = self.suite.index(&name).context("restarted instance")?;
            self.suite.state.instances[i].restarts += 1;
            let r = self.records.entry(name.clone()).or_default();
            r.restart_at = None;
            r.started_at = Some(Instant::now());
            r.healthy = false;
            if let Some(f) = r.open_fault
                && let Some(fault) = self.faults.get_mut(f)
            {
                fault.restarted_at = Some(Instant::now());
            }
            writeln!(out, "supervisor: restarted {name} (pid {pid})")?;
            self.save_state()?;
        }
        Ok(())
    }
}
