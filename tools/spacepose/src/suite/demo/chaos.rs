//! Fault injection in the demo (`--chaos kill:tracker-a@5`, `stop:NAME@K`)
//! and the run-time swap (`--swap ct-ndt@5`), with what the run reports
//! about each: detection and restart times.

use super::super::supervisor::Fault;
use anyhow::{Result, bail};
use serde::Serialize;
use std::time::Instant;

/// The fault to inject.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Action {
    /// SIGKILL (`kill -9`).
    Kill,
    /// SIGSTOP: the process freezes (a hang).
    Stop,
}

/// `ACTION:INSTANCE@FRAME`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChaosSpec {
    /// What to do.
    pub action: Action,
    /// To which instance.
    pub instance: String,
    /// Once this frame has been published by the sensor.
    pub at_frame: u64,
}

fn split_at_frame(s: &str, what: &str) -> Result<(String, u64)> {
    let Some((head, frame)) = s.rsplit_once('@') else {
        bail!("{what} {s:?}: expected ...@FRAME");
    };
    let Ok(frame) = frame.parse::<u64>() else {
        bail!("{what} {s:?}: {frame:?} is not a frame number");
    };
    if head.is_empty() {
        bail!("{what} {s:?}: nothing before '@'");
    }
    Ok((head.to_string(), frame))
}

impl ChaosSpec {
    /// Parses `kill:NAME@K` or `stop:NAME@K`.
    pub fn parse(s: &str) -> Result<Self> {
        let (head, at_frame) = split_at_frame(s, "--chaos")?;
        let (action, instance) = match head.split_once(':') {
            Some(("kill", n)) => (Action::Kill, n),
            Some(("stop", n)) => (Action::Stop, n),
            _ => bail!("--chaos {s:?}: expected kill:NAME@FRAME or stop:NAME@FRAME"),
        };
        if instance.is_empty() {
            bail!("--chaos {s:?}: no instance name");
        }
        Ok(Self {
            action,
            instance: instance.to_string(),
            at_frame,
        })
    }
}

/// `MODE@FRAME`: swap the primary tracker for one in `MODE`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SwapSpec {
    /// Tracking mode of the new instance.
    pub mode: String,
    /// Once this frame has been published.
    pub at_frame: u64,
}

impl SwapSpec {
    /// Parses `MODE@K`.
    pub fn parse(s: &str) -> Result<Self> {
        let (mode, at_frame) = split_at_frame(s, "--swap")?;
        if mode.parse::<spacepose_messages::TrackingMode>().is_err() {
            bail!("--swap {s:?}: unknown mode {mode:?} (ndt, deblur, ct-ndt, icp)");
        }
        Ok(Self { mode, at_frame })
    }
}

/// What happened after one injected fault (the run's JSON).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChaosReport {
    /// Fault.
    pub action: Action,
    /// Instance.
    pub instance: String,
    /// Frame after which it was injected.
    pub at_frame: u64,
    /// Whether it was injected (the run may end first).
    pub injected: bool,
    /// How the supervisor noticed (`exit: …`, `hung`); empty if it did not.
    pub detected_by: String,
    /// Injection → detection by the supervisor (ms).
    pub detection_ms: Option<f64>,
    /// Detection → replacement process started (ms, includes the backoff).
    pub respawn_ms: Option<f64>,
    /// Detection → first heartbeat of the replacement (ms): the restart time.
    pub restart_ms: Option<f64>,
    /// Supervisor's decision (`restart`, `leave`, `give up`).
    pub decision: String,
    /// Frames whose cloud came after the injection until the fault was
    /// detected: the filter's frame deadline covers them (standby takes over).
    pub first_frame_after: Option<u64>,
    /// Injection → that frame's cloud published (ms): for a killed sensor,
    /// the outage the pipeline saw (a restarted sensor resumes at the frame
    /// then due, it does not replay).
    pub first_frame_after_ms: Option<f64>,
    /// Cloud published → fused filter state, for the first frame after
    /// the injection (ms): the standby's takeover time when the primary
    /// tracker was hit.
    pub takeover_ms: Option<f64>,
}

/// An injection in progress.
#[derive(Debug, Clone)]
pub struct Injection {
    /// The spec.
    pub spec: ChaosSpec,
    /// When it was injected.
    pub at: Option<Instant>,
    /// Injection time on CLOCK_REALTIME (ns), to compare with message stamps.
    pub at_ns: i64,
}

fn ms(from: Instant, to: Instant) -> f64 {
    to.saturating_duration_since(from).as_secs_f64() * 1e3
}

impl Injection {
    /// The report, from the supervisor's faults and the frames'
    /// (cloud published ns, fused ns) by sequence.
    pub fn report(&self, faults: &[Fault], fused: &[(u64, i64, Option<i64>)]) -> ChaosReport {
        let fault = self.at.and_then(|at| {
            faults
                .iter()
                .find(|f| f.instance == self.spec.instance && f.detected_at >= at)
        });
        let first_after = self.at.and_then(|_| {
            fused
                .iter()
                .find(|(_, cloud_ns, _)| *cloud_ns >= self.at_ns)
        });
        ChaosReport {
            action: self.spec.action,
            instance: self.spec.instance.clone(),
            at_frame: self.spec.at_frame,
            injected: self.at.is_some(),
            detected_by: fault.map(|f| f.cause.clone()).unwrap_or_default(),
            detection_ms: fault.zip(self.at).map(|(f, at)| ms(at, f.detected_at)),
            respawn_ms: fault.and_then(|f| f.restarted_at.map(|t| ms(f.detected_at, t))),
            restart_ms: fault.and_then(|f| f.healthy_at.map(|t| ms(f.detected_at, t))),
            decision: fault.map(|f| f.decision.clone()).unwrap_or_default(),
            first_frame_after: first_after.map(|f| f.0),
            first_frame_after_ms: first_after
                .map(|(_, cloud, _)| (cloud - self.at_ns) as f64 * 1e-6),
            takeover_ms: first_after
                .and_then(|(_, cloud, fused)| fused.map(|f| (f - cloud) as f64 * 1e-6)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_parse_and_bad_ones_are_named() {
        let c = ChaosSpec::parse("kill:tracker-a@5").unwrap();
        assert_eq!(
            (c.action, c.instance.as_str(), c.at_frame),
            (Action::Kill, "tracker-a", 5)
        );
        assert_eq!(ChaosSpec::parse("stop:x@0").unwrap().action, Action::Stop);
        for bad in ["kill:tracker-a", "pause:x@1", "kill:@3", "kill:x@y", "@4"] {
            let e = ChaosSpec::parse(bad).unwrap_err();
            assert!(e.to_string().contains(bad), "{e}");
        }
        let s = SwapSpec::parse("ct-ndt@7").unwrap();
        assert_eq!((s.mode.as_str(), s.at_frame), ("ct-ndt", 7));
        assert!(SwapSpec::parse("warp@7").is_err());
    }
}
