//! The filter service's logic without any bus: what to do with each
//! acquisition result and tracker estimate, and the state to publish.
//! `src/main.rs` only moves messages between the bus and [`FilterNode`].

use crate::config::FilterConfig;
use crate::error::FilterError;
use crate::filter::RelativeMotionFilter;
use crate::selector::{EstimateSelector, Selection};
use crate::wire::{acquisition_pose, measurement_from_estimate, state_of, zero_rates};
use serde::{Deserialize, Serialize};
use spacepose_messages::{AcquisitionResult, FilterState, PoseEstimate, WireStatus};

/// Configuration of the `spacepose-filter` service (TOML).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FilterServiceConfig {
    /// Filter tuning. The default turns the innovation gate off, as the
    /// tracker's own filter does: the registration covariance is
    /// over-confident, and the tracker already rejects inconsistent frames
    /// (they arrive as `degraded` and are not fused).
    pub filter: FilterConfig,
    /// Period of the `FilterState` heartbeat (ms), so late joiners (a
    /// restarted tracker, telemetry) get the state without waiting for an
    /// update. 0 disables it.
    pub state_period_ms: u64,
    /// Frames remembered by the one-estimate-per-frame selector.
    pub selector_window: usize,
}

impl Default for FilterServiceConfig {
    fn default() -> Self {
        Self {
            filter: FilterConfig {
                gate_mahalanobis2: None,
                ..FilterConfig::default()
            },
            state_period_ms: 500,
            selector_window: 64,
        }
    }
}

impl FilterServiceConfig {
    /// Checks every value.
    pub fn validate(&self) -> Result<(), FilterError> {
        self.filter.validate()?;
        if self.selector_window == 0 {
            return Err(FilterError::InvalidConfig(
                "selector_window must be >= 1".into(),
            ));
        }
        Ok(())
    }
}

/// What [`FilterNode::on_estimate`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EstimateOutcome {
    /// Fused into the filter: publish the new state.
    Fused,
    /// The estimate refers to the time the filter was (re)initialised at,
    /// before any update: it replaced the initial pose. Publish the state.
    Reinitialized,
    /// The filter's innovation gate refused it (state unchanged).
    Gated {
        /// Squared Mahalanobis distance of the innovation.
        mahalanobis2: f64,
    },
    /// Another estimate of the same frame was selected first.
    Duplicate,
    /// Older than the selector's window.
    Stale,
    /// Not a `tracking` estimate: reported, not fused (as in the tracker).
    NotTracking(WireStatus),
    /// The filter has not been initialised by an acquisition yet.
    NotInitialized,
    /// At or before the time of the current state (and not the initial frame).
    TooOld {
        /// `t_estimate - t_filter` (s).
        dt_s: f64,
    },
}

impl EstimateOutcome {
    /// True when the state changed and should be published.
    pub fn changed_state(self) -> bool {
        matches!(self, Self::Fused | Self::Reinitialized)
    }
}

/// The filter service: the authoritative relative-motion state.
#[derive(Debug, Clone)]
pub struct FilterNode {
    filter: RelativeMotionFilter,
    selector: EstimateSelector,
    updates: u64,
    /// Time of the last (re)initialisation while no estimate has been fused since.
    fresh_init_t: Option<f64>,
}

impl FilterNode {
    /// An uninitialised node.
    pub fn new(config: &FilterServiceConfig) -> Result<Self, FilterError> {
        config.validate()?;
        Ok(Self {
            filter: RelativeMotionFilter::new(config.filter.clone())?,
            selector: EstimateSelector::new(config.selector_window),
            updates: 0,
            fresh_init_t: None,
        })
    }

    /// The filter.
    pub fn filter(&self) -> &RelativeMotionFilter {
        &self.filter
    }

    /// States changes (initialisations and fused estimates) so far.
    pub fn updates(&self) -> u64 {
        self.updates
    }

    /// The state to publish (uninitialised until an acquisition arrives).
    pub fn state(&self) -> FilterState {
        state_of(&self.filter, self.updates)
    }

    /// (Re)initialises on a successful acquisition, at ω = v = 0 (seed 000
    /// §5.2). Returns whether the state changed. Errors on a bad message.
    pub fn on_acquisition(&mut self, a: &AcquisitionResult) -> Result<bool, FilterError> {
        let Some((t, pose)) = acquisition_pose(a)? else {
            return Ok(false);
        };
        let (v, w) = zero_rates();
        self.filter.initialize(t, &pose, v, w)?;
        self.selector.reset();
        self.fresh_init_t = Some(t);
        self.updates += 1;
        Ok(true)
    }

    /// Selects, checks and fuses a tracker estimate. Errors on a bad message
    /// or a filter failure (the state is then unchanged).
    pub fn on_estimate(&mut self, e: &PoseEstimate) -> Result<EstimateOutcome, FilterError> {
        let m = measurement_from_estimate(e)?;
        match self.selector.offer(e.sequence) {
            Selection::Selected => {}
            Selection::Duplicate => return Ok(EstimateOutcome::Duplicate),
            Selection::Stale => return Ok(EstimateOutcome::Stale),
        }
        if m.status != WireStatus::Tracking {
            return Ok(EstimateOutcome::NotTracking(m.status));
        }
        let Some(t_filter) = self.filter.time() else {
            return Ok(EstimateOutcome::NotInitialized);
        };
        if m.t <= t_filter {
            // The acquisition's own frame (or one before it) tracked by the
            // tracker: a registration beats the acquisition's pose.
            if self.fresh_init_t.is_some() {
                let (v, w) = zero_rates();
                self.filter.initialize(m.t, &m.t_sensor_target, v, w)?;
                self.fresh_init_t = Some(m.t);
                self.updates += 1;
                return Ok(EstimateOutcome::Reinitialized);
            }
            return Ok(EstimateOutcome::TooOld {
                dt_s: m.t - t_filter,
            });
        }
        let outcome = self.filter.update(m.t, &m.t_sensor_target, m.covariance)?;
        if !outcome.fused {
            return Ok(EstimateOutcome::Gated {
                mahalanobis2: outcome.mahalanobis2,
            });
        }
        self.fresh_init_t = None;
        self.updates += 1;
        Ok(EstimateOutcome::Fused)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use spacepose_geometry::{Pose, so3};

    fn pose_at(t: f64) -> Pose {
        Pose::new(
            so3::exp(&Vector3::new(0.0, 0.0, 0.1 * t)),
            Vector3::new(0.0, 0.0, 20.0 - 0.1 * t),
        )
    }

    fn estimate(seq: u64, t: f64, status: WireStatus) -> PoseEstimate {
        let mut e = PoseEstimate::new();
        e.sequence = seq;
        e.t_s = t;
        e.status = status as u8;
        e.set_pose(&pose_at(t));
        e
    }

    fn acquisition(t: f64) -> AcquisitionResult {
        let mut a = AcquisitionResult::new();
        a.success = 1;
        a.t_s = t;
        a.set_pose(&pose_at(t));
        a
    }

    #[test]
    fn acquisition_then_tracking_estimates_are_fused() {
        let mut node = FilterNode::new(&FilterServiceConfig::default()).unwrap();
        assert_eq!(node.state().initialized, 0);
        let e1 = estimate(1, 1.0, WireStatus::Tracking);
        assert_eq!(
            node.on_estimate(&e1).unwrap(),
            EstimateOutcome::NotInitialized
        );
        let mut failed = acquisition(0.0);
        failed.success = 0;
        assert!(!node.on_acquisition(&failed).unwrap());
        assert!(node.on_acquisition(&acquisition(0.0)).unwrap());
        for k in 1..6u64 {
            let e = estimate(k, k as f64, WireStatus::Tracking);
            assert_eq!(node.on_estimate(&e).unwrap(), EstimateOutcome::Fused);
            assert_eq!(node.on_estimate(&e).unwrap(), EstimateOutcome::Duplicate);
        }
        let s = node.state();
        assert_eq!((s.initialized, s.sequence, s.t_s), (1, 6, 5.0));
        // The filter learnt the rotation rate (0.1 rad/s about z, sensor frame
        // = target frame here since R is about z).
        assert!((s.w_target[2] - 0.1).abs() < 0.05, "{:?}", s.w_target);
    }

    #[test]
    fn degraded_lost_old_and_bad_estimates_change_nothing() {
        let mut node = FilterNode::new(&FilterServiceConfig::default()).unwrap();
        node.on_acquisition(&acquisition(0.0)).unwrap();
        node.on_estimate(&estimate(1, 1.0, WireStatus::Tracking))
            .unwrap();
        let before = node.state();
        for status in [WireStatus::Degraded, WireStatus::Lost] {
            let e = estimate(2 + status as u64, 2.0, status);
            assert_eq!(
                node.on_estimate(&e).unwrap(),
                EstimateOutcome::NotTracking(status)
            );
        }
        let old = estimate(9, 0.5, WireStatus::Tracking);
        assert!(matches!(
            node.on_estimate(&old).unwrap(),
            EstimateOutcome::TooOld { .. }
        ));
        let mut bad = estimate(10, 3.0, WireStatus::Tracking);
        bad.p_sensor_target[0] = f64::NAN;
        assert!(node.on_estimate(&bad).is_err());
        assert_eq!(node.state(), before);
    }

    #[test]
    fn the_acquisition_frame_itself_replaces_the_initial_pose() {
        let mut node = FilterNode::new(&FilterServiceConfig::default()).unwrap();
        node.on_acquisition(&acquisition(2.0)).unwrap();
        let mut e = estimate(2, 2.0, WireStatus::Tracking);
        e.p_sensor_target[2] += 0.05;
        assert_eq!(
            node.on_estimate(&e).unwrap(),
            EstimateOutcome::Reinitialized
        );
        assert_eq!(node.state().p_sensor_target, e.p_sensor_target);
        let next = estimate(3, 3.0, WireStatus::Tracking);
        assert_eq!(node.on_estimate(&next).unwrap(), EstimateOutcome::Fused);
        // After a fused update the same time is simply too old.
        let again = estimate(4, 3.0, WireStatus::Tracking);
        assert!(matches!(
            node.on_estimate(&again).unwrap(),
            EstimateOutcome::TooOld { .. }
        ));
    }
}
