//! The innovation limit that follows the track (not in the papers;
//! `docs/design/innovation-limit.md`).
//!
//! `loss.max_innovation_rot_deg` (15°) is absolute: a registration that
//! slides a few degrees a frame away from a good prediction passes it, and
//! is fused, and the next prediction follows it. On the generated targets
//! the registrations slid 5-8° a frame, and every frame was published
//! `tracking` until the error passed 10° and more. Once the filter's rate
//! is known, the prediction is good to a fraction of a degree, and the
//! track's own innovations say how good: the limit is then a multiple of
//! their recent median, never below a floor (noise and modelling errors)
//! nor above the absolute limit. The covariance is not used: even scaled
//! to a consistent NEES, the innovations' NIS sits far under χ²(6) (the
//! registration's errors are correlated from frame to frame,
//! `docs/design/measurement-covariance.md`), so a χ² test would let a
//! slide of several degrees through.

use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// The `[tracker.loss.innovation]` table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct InnovationLimitConfig {
    /// Follow the track's innovations (else the absolute limit alone).
    pub enabled: bool,
    /// Innovations remembered (frames tracked after the start-up).
    pub window: usize,
    /// Fewest remembered innovations before the limit follows them.
    pub min_samples: usize,
    /// The limit is this times the remembered median.
    pub median_factor: f64,
    /// The limit is never below this (deg).
    pub floor_deg: f64,
}

impl Default for InnovationLimitConfig {
    fn default() -> Self {
        Self {
            enabled: true,
            window: 20,
            min_samples: 5,
            median_factor: 5.0,
            floor_deg: 3.0,
        }
    }
}

impl InnovationLimitConfig {
    /// A description of the first bad value.
    pub fn problem(&self) -> Option<String> {
        let ok = self.window >= 1
            && (1..=self.window).contains(&self.min_samples)
            && self.median_factor.is_finite()
            && self.median_factor >= 1.0
            && self.floor_deg.is_finite()
            && self.floor_deg > 0.0;
        (!ok).then(|| {
            format!(
                "loss.innovation: window >= 1, 1 <= min_samples <= window, finite \
                 median_factor >= 1 and floor_deg > 0: {self:?}"
            )
        })
    }
}

/// The recent attitude innovations of a track.
#[derive(Debug, Clone, Default)]
pub struct InnovationHistory {
    recent_deg: VecDeque<f64>,
}

impl InnovationHistory {
    /// Forgets the track (a (re)initialisation).
    pub fn reset(&mut self) {
        self.recent_deg.clear();
    }

    /// Remembers the innovation of a frame tracked after the start-up.
    pub fn record(&mut self, config: &InnovationLimitConfig, innovation_deg: f64) {
        if !innovation_deg.is_finite() {
            return;
        }
        self.recent_deg.push_back(innovation_deg);
        while self.recent_deg.len() > config.window {
            self.recent_deg.pop_front();
        }
    }

    /// The attitude innovation limit (deg) for the next frame: `absolute_deg`
    /// in the start-up and until `min_samples` innovations are known, then
    /// `median_factor` × their median within `[floor_deg, absolute_deg]`.
    pub fn limit_deg(
        &self,
        config: &InnovationLimitConfig,
        absolute_deg: f64,
        start_up: bool,
    ) -> f64 {
        if !config.enabled || start_up || self.recent_deg.len() < config.min_samples {
            return absolute_deg;
        }
        let mut v: Vec<f64> = self.recent_deg.iter().copied().collect();
        v.sort_by(f64::total_cmp);
        let median = v[v.len() / 2];
        (config.median_factor * median)
            .max(config.floor_deg)
            .min(absolute_deg)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_limit_is_absolute_until_the_track_has_a_history() {
        let c = InnovationLimitConfig::default();
        let mut h = InnovationHistory::default();
        for _ in 0..c.min_samples - 1 {
            h.record(&c, 0.2);
        }
        assert_eq!(h.limit_deg(&c, 15.0, false), 15.0);
        h.record(&c, 0.2);
        assert_eq!(h.limit_deg(&c, 15.0, false), c.floor_deg);
        assert_eq!(h.limit_deg(&c, 15.0, true), 15.0, "start-up");
        h.reset();
        assert_eq!(h.limit_deg(&c, 15.0, false), 15.0);
    }

    #[test]
    fn the_limit_follows_the_median_between_the_floor_and_the_absolute_limit() {
        let c = InnovationLimitConfig::default();
        let mut h = InnovationHistory::default();
        for d in [1.0, 1.2, 0.8, 50.0, 1.1, f64::NAN] {
            h.record(&c, d);
        }
        assert_eq!(h.limit_deg(&c, 15.0, false), 5.5, "5 × median 1.1");
        for _ in 0..c.window {
            h.record(&c, 4.0);
        }
        assert_eq!(h.limit_deg(&c, 15.0, false), 15.0);
        let off = InnovationLimitConfig {
            enabled: false,
            ..c.clone()
        };
        assert_eq!(h.limit_deg(&off, 15.0, false), 15.0);
    }

    #[test]
    fn bad_values_are_named() {
        assert!(InnovationLimitConfig::default().problem().is_none());
        for c in [
            InnovationLimitConfig {
                floor_deg: f64::NAN,
                ..Default::default()
            },
            InnovationLimitConfig {
                min_samples: 30,
                ..Default::default()
            },
            InnovationLimitConfig {
                median_factor: 0.5,
                ..Default::default()
            },
        ] {
            assert!(c.problem().is_some());
        }
    }
}
