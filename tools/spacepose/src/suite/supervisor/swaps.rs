//! The supervisor's side of an estimator swap: queueing the swap job,
//! driving it every step, and what the job may do to the suite
//! ([`SwapHost`]).

use super::{Record, Supervisor};
use crate::suite::plan::PlannedInstance;
use crate::suite::swap::{SwapHost, SwapJob, SwapRequest};
use anyhow::Result;
use rustix::process::Signal;
use spacepose_messages::{Command, PoseEstimate, ServiceKind};
use std::io::Write;
use std::time::Instant;

impl Supervisor {
    /// Queues a swap (one at a time).
    pub fn request_swap(&mut self, req: SwapRequest, out: &mut dyn Write) -> Result<()> {
        if self.swap.is_some() {
            anyhow::bail!("a swap is already running");
        }
        self.swap_count += 1;
        let job = SwapJob::start(self, req, self.swap_count, out)?;
        self.swap = Some(job);
        Ok(())
    }

    /// True while a swap runs.
    pub fn swapping(&self) -> bool {
        self.swap.is_some()
    }

    pub(super) fn step_swap(&mut self, poses: &[PoseEstimate], out: &mut dyn Write) -> Result<()> {
        let Some(mut job) = self.swap.take() else {
            return Ok(());
        };
        match job.step(self, poses, out) {
            Ok(Some(report)) => {
                writeln!(out, "supervisor: {}", report.line())?;
                self.swaps.push(report);
                self.save_state()?;
            }
            Ok(None) => self.swap = Some(job),
            Err(e) => {
                let report = job.fail(self, &format!("{e:#}"));
                writeln!(out, "supervisor: swap failed: {e:#}")?;
                self.swaps.push(report);
            }
        }
        Ok(())
    }
}

impl SwapHost for Supervisor {
    /// Starts a new instance (not in the original plan).
    fn add_instance(&mut self, planned: PlannedInstance) -> Result<u32> {
        let pid = self.suite.spawn_instance(&self.plan, &planned)?;
        self.records.insert(
            planned.name.clone(),
            Record {
                started_at: Some(Instant::now()),
                ..Record::default()
            },
        );
        self.plan.instances.retain(|i| i.name != planned.name);
        self.plan.instances.push(planned);
        self.save_state()?;
        Ok(pid)
    }

    /// Stops an instance on purpose (SIGTERM; its exit is no fault).
    fn retire(&mut self, name: &str) {
        if let Some(r) = self.records.get_mut(name) {
            r.retiring = true;
            r.restart_at = None;
            // A left-down instance's exit is handled again, as retiring.
            r.down = false;
        }
        self.plan.instances.retain(|i| i.name != name);
        // An exited process's group id may belong to another process now.
        if self.suite.try_exit(name).is_none() {
            self.suite.signal(name, Signal::TERM);
        }
    }

    /// True once `name` has exited and been forgotten.
    fn is_gone(&self, name: &str) -> bool {
        self.suite.index(name).is_none()
    }

    /// Makes `name` the filter's primary: the swap command, and the filter's
    /// config for its restarts.
    fn set_primary(&mut self, name: &str) -> Result<()> {
        let mut c = Command::new(
            spacepose_messages::CommandKind::Swap,
            spacepose_messages::Name::new("supervisor")?,
        );
        c.target_instance = spacepose_messages::Name::new(name)?;
        self.commands.send(&c)?;
        for f in self
            .plan
            .instances
            .iter_mut()
            .filter(|i| i.kind == ServiceKind::Filter)
        {
            f.config
                .insert("primary".into(), toml::Value::String(name.to_string()));
        }
        self.primary = Some(name.to_string());
        self.save_state()
    }

    /// The primary, or the only instance, of `kind`.
    fn active_instance(&self, kind: ServiceKind) -> Option<String> {
        let of_kind: Vec<&str> = self
            .suite
            .state
            .instances
            .iter()
            .filter(|i| i.kind == kind)
            .map(|i| i.name.as_str())
            .collect();
        match &self.primary {
            Some(p) if of_kind.contains(&p.as_str()) => Some(p.clone()),
            _ => of_kind.first().map(|s| s.to_string()),
        }
    }

    fn planned(&self, name: &str) -> Option<&PlannedInstance> {
        Supervisor::planned(self, name)
    }

    fn primary(&self) -> Option<&str> {
        self.primary.as_deref()
    }
}
