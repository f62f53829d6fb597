//! Estimator swap at run time (`spacepose swap tracker --mode ct-ndt`):
//! 1. start the new instance (`{kind}-s{n}`, the old one's configuration
//!    with the new mode, or another binary);
//! 2. warm: it starts from the filter service's state like any fresh
//!    tracker, and is ready at its first `tracking` pose;
//! 3. switch: a `swap` command makes it the filter's primary from the next
//!    undecided frame (a frame boundary);
//! 4. stop the old instance once the new one has answered a frame that the
//!    filter took under the new roles (two frames after the command).
//!
//! The old instance keeps publishing until step 4, and the filter falls back
//! to a standby at the frame deadline anyway: no frame goes without a pose.

use super::plan::PlannedInstance;
use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use spacepose_messages::ServiceKind;
use spacepose_messages::{PoseEstimate, TrackingMode, WireStatus};
use std::io::Write;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// How long the new instance gets to produce its first tracking pose.
pub const WARM_TIMEOUT: Duration = Duration::from_secs(60);

/// What to swap in.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SwapRequest {
    /// Kind of service (trackers only for now).
    pub kind: ServiceKind,
    /// New tracking mode (`ndt`, `deblur`, `ct-ndt`, `icp`).
    pub mode: Option<String>,
    /// New binary (a new build).
    pub binary: Option<PathBuf>,
}

/// The result of a swap (also written for `spacepose swap`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SwapReport {
    /// Old instance.
    pub old: String,
    /// New instance.
    pub new: String,
    /// Request → first tracking pose of the new instance (ms).
    pub warm_ms: f64,
    /// Swap command → old instance told to stop (ms).
    pub switch_ms: f64,
    /// Request → old instance exited (ms).
    pub total_ms: f64,
    /// Frame sequence at the switch command.
    pub switch_frame: u64,
    /// Why it failed (the old instance then stays primary).
    pub error: Option<String>,
}

impl SwapReport {
    /// One line for logs.
    pub fn line(&self) -> String {
        match &self.error {
            Some(e) => format!("swap {} -> {} failed: {e}", self.old, self.new),
            None => format!(
                "swap {} -> {} done: warm {:.0} ms, switch {:.0} ms, total {:.0} ms (switch at frame {})",
                self.old, self.new, self.warm_ms, self.switch_ms, self.total_ms, self.switch_frame
            ),
        }
    }
}

/// What a swap job does to the suite it runs in: the supervisor
/// implements it (`supervisor/swaps.rs`).
pub trait SwapHost {
    /// Starts a new instance (not in the original plan).
    fn add_instance(&mut self, planned: PlannedInstance) -> Result<u32>;
    /// Stops an instance on purpose (SIGTERM; its exit is no fault).
    fn retire(&mut self, name: &str);
    /// True once `name` has exited and been forgotten.
    fn is_gone(&self, name: &str) -> bool;
    /// Makes `name` the filter's primary: the swap command, and the filter's
    /// config for its restarts.
    fn set_primary(&mut self, name: &str) -> Result<()>;
    /// The primary, or the only instance, of `kind`.
    fn active_instance(&self, kind: ServiceKind) -> Option<String>;
    /// The planned instance `name`.
    fn planned(&self, name: &str) -> Option<&PlannedInstance>;
    /// The filter's primary tracker.
    fn primary(&self) -> Option<&str>;
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    Warming,
    Switching { at: Instant, frame: u64 },
    Stopping,
}

/// A swap in progress, driven by [`super::supervisor::Supervisor::step`].
#[derive(Debug)]
pub struct SwapJob {
    old: String,
    new: String,
    requested: Instant,
    warm_at: Option<Instant>,
    switch_ms: f64,
    switch_frame: u64,
    newest_frame: u64,
    phase: Phase,
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The configuration of the new instance: the old one's with `mode` set.
pub fn swapped_config(old: &toml::Table, mode: Option<&str>) -> Result<toml::Table> {
    let mut config = old.clone();
    if let Some(mode) = mode {
        if mode.parse::<TrackingMode>().is_err() {
            bail!("--mode {mode:?}: unknown mode (ndt, deblur, ct-ndt, icp)");
        }
        let tracker = config
            .entry("tracker")
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        let Some(t) = tracker.as_table_mut() else {
            bail!("the tracker's `tracker` config key is not a table");
        };
        t.insert("mode".into(), toml::Value::String(mode.to_string()));
    }
    Ok(config)
}

impl SwapJob {
    /// Starts the new instance.
    pub fn start(
        sup: &mut impl SwapHost,
        req: SwapRequest,
        n: u32,
        out: &mut dyn Write,
    ) -> Result<SwapJob> {
        if req.kind != ServiceKind::Tracker {
            bail!("only trackers can be swapped (asked: {})", req.kind);
        }
        let old = sup
            .active_instance(req.kind)
            .with_context(|| format!("no {} instance is running", req.kind))?;
        let planned = sup
            .planned(&old)
            .cloned()
            .with_context(|| format!("{old} is not in the plan"))?;
        let mut new = format!("{}-s{n}", req.kind);
        while !sup.is_gone(&new) {
            new.push('x');
        }
        let config = swapped_config(&planned.config, req.mode.as_deref())?;
        let binary = match &req.binary {
            Some(b) if b.is_file() => b.clone(),
            Some(b) => bail!("--binary {}: no such file", b.display()),
            None => planned.binary.clone(),
        };
        let pid = sup.add_instance(PlannedInstance {
            name: new.clone(),
            kind: req.kind,
            binary,
            config,
            restart_policy: planned.restart_policy,
        })?;
        writeln!(
            out,
            "supervisor: swap {old} -> {new}: started {new} (pid {pid}, mode {})",
            req.mode.as_deref().unwrap_or("unchanged")
        )?;
        Ok(SwapJob {
            old,
            new,
            requested: Instant::now(),
            warm_at: None,
            switch_ms: f64::NAN,
            switch_frame: 0,
            newest_frame: 0,
            phase: Phase::Warming,
        })
    }

    /// Advances the swap; `Some(report)` when it is over.
    pub fn step(
        &mut self,
        sup: &mut impl SwapHost,
        poses: &[PoseEstimate],
        out: &mut dyn Write,
    ) -> Result<Option<SwapReport>> {
        let mut new_frame = None;
        for p in poses {
            self.newest_frame = self.newest_frame.max(p.sequence);
            let tracked = WireStatus::from_u8(p.status).is_ok_and(WireStatus::is_tracked);
            if p.instance.as_str() == self.new && tracked {
                new_frame = Some(new_frame.unwrap_or(0).max(p.sequence));
            }
        }
        if sup.is_gone(&self.new) && self.phase != Phase::Stopping {
            bail!("{} exited during the swap", self.new);
        }
        match self.phase {
            Phase::Warming => {
                if new_frame.is_some() {
                    self.warm_at = Some(Instant::now());
                    sup.set_primary(&self.new)?;
                    self.switch_frame = self.newest_frame;
                    self.phase = Phase::Switching {
                        at: Instant::now(),
                        frame: self.newest_frame,
                    };
                    writeln!(
                        out,
                        "supervisor: swap: {} is warm; primary from the frame after {}",
                        self.new, self.newest_frame
                    )?;
                } else if self.requested.elapsed() > WARM_TIMEOUT {
                    bail!(
                        "{} produced no tracking pose within {} s",
                        self.new,
                        WARM_TIMEOUT.as_secs()
                    );
                }
            }
            Phase::Switching { at, frame } => {
                if new_frame.is_some_and(|f| f >= frame + 2) {
                    self.switch_ms = ms(at.elapsed());
                    sup.retire(&self.old);
                    self.phase = Phase::Stopping;
                }
            }
            Phase::Stopping => {
                if sup.is_gone(&self.old) {
                    return Ok(Some(self.report(None)));
                }
            }
        }
        Ok(None)
    }

    /// Gives up: the new instance is stopped; the old one stays (primary again).
    pub fn fail(&self, sup: &mut impl SwapHost, why: &str) -> SwapReport {
        if !sup.is_gone(&self.new) {
            sup.retire(&self.new);
        }
        if sup.primary() == Some(self.new.as_str()) && !sup.is_gone(&self.old) {
            let _ = sup.set_primary(&self.old);
        }
        self.report(Some(why.to_string()))
    }

    fn report(&self, error: Option<String>) -> SwapReport {
        SwapReport {
            old: self.old.clone(),
            new: self.new.clone(),
            warm_ms: self
                .warm_at
                .map_or(f64::NAN, |t| ms(t.duration_since(self.requested))),
            switch_ms: self.switch_ms,
            total_ms: ms(self.requested.elapsed()),
            switch_frame: self.switch_frame,
            error,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_new_config_changes_only_the_mode() {
        let old: toml::Table = toml::from_str(
            "target = \"deos\"\n[tracker]\nmode = \"deblur\"\nmax_iterations = 30\n",
        )
        .unwrap();
        let new = swapped_config(&old, Some("ct-ndt")).unwrap();
        assert_eq!(new["tracker"]["mode"].as_str(), Some("ct-ndt"));
        assert_eq!(new["tracker"]["max_iterations"].as_integer(), Some(30));
        assert_eq!(new["target"], old["target"]);
        assert_eq!(swapped_config(&old, None).unwrap(), old);
        let bare = swapped_config(&toml::Table::new(), Some("icp")).unwrap();
        assert_eq!(bare["tracker"]["mode"].as_str(), Some("icp"));
        assert!(swapped_config(&old, Some("fastest")).is_err());
    }
}
