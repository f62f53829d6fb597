//! Restart policy of supervised services, after dora-rs' `restart_policy`:
//! `never`, `on-failure` (an exit with a non-zero status or a signal, or a
//! hang) or `always`; with an exponential backoff and at most
//! `max_restarts` within a sliding `window_s`, after which the instance is
//! left down (`failed`).

use serde::{Deserialize, Serialize};
use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// When to restart an instance that stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Policy {
    /// Never.
    Never,
    /// After a failure: non-zero exit status, killed by a signal, or hung.
    #[default]
    OnFailure,
    /// After any exit, also a clean one.
    Always,
}

/// The restart settings of a deployment (descriptor table `[restart]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RestartSettings {
    /// Default policy of every instance (a service may set its own
    /// `restart_policy`).
    pub policy: Policy,
    /// Restarts allowed within `window_s`; one more and the instance stays down.
    pub max_restarts: u32,
    /// Length of the sliding window (s).
    pub window_s: f64,
    /// Delay before the first restart in a window (ms); doubles with every
    /// further restart in the window.
    pub backoff_ms: u64,
    /// Cap of the delay (ms).
    pub max_backoff_ms: u64,
}

impl Default for RestartSettings {
    fn default() -> Self {
        Self {
            policy: Policy::OnFailure,
            max_restarts: 5,
            window_s: 60.0,
            backoff_ms: 0,
            max_backoff_ms: 5_000,
        }
    }
}

impl RestartSettings {
    /// Problems with the values, one line each.
    pub fn problems(&self) -> Vec<String> {
        let mut p = Vec::new();
        if !(self.window_s.is_finite() && self.window_s > 0.0) {
            p.push(format!(
                "restart.window_s must be a positive number of seconds, got {}",
                self.window_s
            ));
        }
        if self.max_backoff_ms < self.backoff_ms {
            p.push("restart.max_backoff_ms must be >= restart.backoff_ms".to_string());
        }
        p
    }
}

/// Why an instance stopped.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Stop {
    /// Exit status 0.
    Clean,
    /// Non-zero status or a signal (the text of the exit status).
    Failed(String),
    /// No heartbeat within the deadline (the supervisor killed it).
    Hung,
}

/// What to do about a stopped instance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Decision {
    /// Start it again after this delay.
    RestartAfter(Duration),
    /// Leave it down: the policy says so.
    Leave,
    /// Leave it down: too many restarts within the window.
    GiveUp,
}

/// Restart history of one instance.
#[derive(Debug, Clone, Default)]
pub struct RestartHistory {
    recent: VecDeque<Instant>,
    /// Restarts since the suite started.
    pub total: u32,
}

impl RestartHistory {
    /// Decides for an instance that stopped at `now` with `policy`.
    pub fn decide(
        &mut self,
        settings: &RestartSettings,
        policy: Policy,
        stop: &Stop,
        now: Instant,
    ) -> Decision {
        let wanted = match policy {
            Policy::Never => false,
            Policy::OnFailure => *stop != Stop::Clean,
            Policy::Always => true,
        };
        if !wanted {
            return Decision::Leave;
        }
        let window = Duration::from_secs_f64(settings.window_s);
        while self
            .recent
            .front()
            .is_some_and(|t| now.duration_since(*t) > window)
        {
            self.recent.pop_front();
        }
        if self.recent.len() as u32 >= settings.max_restarts {
            return Decision::GiveUp;
        }
        let shift = self.recent.len().min(20) as u32;
        let delay_ms = settings
            .backoff_ms
            .saturating_mul(1u64 << shift)
            .min(settings.max_backoff_ms);
        self.recent.push_back(now);
        self.total += 1;
        Decision::RestartAfter(Duration::from_millis(delay_ms))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings() -> RestartSettings {
        RestartSettings {
            max_restarts: 3,
            window_s: 10.0,
            backoff_ms: 100,
            max_backoff_ms: 250,
            ..RestartSettings::default()
        }
    }

    #[test]
    fn failures_restart_with_backoff_until_the_window_is_full() {
        let s = settings();
        let mut h = RestartHistory::default();
        let t0 = Instant::now();
        let failed = Stop::Failed("signal: 9 (SIGKILL)".into());
        let d: Vec<Decision> = (0..4)
            .map(|k| h.decide(&s, Policy::OnFailure, &failed, t0 + Duration::from_secs(k)))
            .collect();
        let ms = Duration::from_millis;
        assert_eq!(
            d,
            [
                Decision::RestartAfter(ms(100)),
                Decision::RestartAfter(ms(200)),
                Decision::RestartAfter(ms(250)),
                Decision::GiveUp
            ]
        );
        assert_eq!(h.total, 3);
        // Once the first restarts leave the window, restarts resume, with
        // the backoff of the one still inside it (at 2 s).
        let later = t0 + Duration::from_secs(12);
        assert_eq!(
            h.decide(&s, Policy::OnFailure, &Stop::Hung, later),
            Decision::RestartAfter(ms(200))
        );
    }

    #[test]
    fn policies_decide_which_stops_restart() {
        let s = settings();
        let now = Instant::now();
        let mut h = RestartHistory::default();
        assert_eq!(
            h.decide(&s, Policy::OnFailure, &Stop::Clean, now),
            Decision::Leave
        );
        assert_eq!(
            h.decide(&s, Policy::Never, &Stop::Hung, now),
            Decision::Leave
        );
        assert!(matches!(
            h.decide(&s, Policy::Always, &Stop::Clean, now),
            Decision::RestartAfter(_)
        ));
        assert!(settings().problems().is_empty());
        let bad = RestartSettings {
            window_s: f64::NAN,
            max_backoff_ms: 1,
            ..settings()
        };
        assert_eq!(bad.problems().len(), 2);
    }
}
