//! When a frame counts as degraded and the track as lost: [`LossConfig`],
//! its defaults and its checks.

use crate::error::TrackError;
use crate::innovation::InnovationLimitConfig;
use serde::{Deserialize, Serialize};

/// When a frame counts as degraded, and when the track counts as lost.
///
/// The shape-dependent bounds (mean NDT cost, inlier fraction) come from
/// the target package, calibrated from simulated frames of that target
/// (`docs/design/target-packages.md`); the others were set from simulated
/// `deos` frames of the slow-spin scenario with seed 1 only: failed
/// registrations show a collapsed inlier fraction, a high cost, or a jump
/// away from the prediction; a 60° symmetric flip of the hexagonal body (seed 000 §5.2)
/// is far above the innovation limits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LossConfig {
    /// Fewest points after pre-processing (the voxel filter) for a
    /// registration to be attempted. A cloud with fewer carries no
    /// measurement (the target is not in view: ingest forwards such frames
    /// as observations, e.g. when the sensor looks away): the frame is
    /// declared `lost` at once, not after `max_consecutive_degraded` frames,
    /// since there is nothing to track, and nothing is fused. >= 1. Default
    /// 20, the init service's `min_points` (issue 5: under 20 points a cloud
    /// is too sparse to match).
    pub min_points: usize,
    /// Fewest inliers for a usable registration.
    pub min_inliers: usize,
    /// Smallest fraction of the filtered points that must find a cell.
    /// Unset (the default): the target package's calibrated value
    /// ([`crate::TrackingModel::thresholds`]).
    pub min_inlier_fraction: Option<f64>,
    /// Largest mean NDT cost per inlier (Mahalanobis, unitless). Unset (the
    /// default): the target package's calibrated value, since the cost of a
    /// good fit depends on the target's shape (curved surfaces fit the
    /// planar NDT cells worse).
    pub max_mean_cost_ndt: Option<f64>,
    /// Largest mean squared distance for ICP (m²).
    pub max_mean_cost_icp_m2: f64,
    /// Largest attitude jump from the filter prediction (deg).
    pub max_innovation_rot_deg: f64,
    /// Largest position jump from the filter prediction (m).
    pub max_innovation_pos_m: f64,
    /// A registration that stops at its iteration limit is only doubted
    /// when its last increment is still above this angle (deg): reaching the
    /// limit on a sparse frame is normal (seed 000 Table 2), still moving by
    /// degrees is not.
    pub max_final_increment_deg: f64,
    /// See [`Self::max_final_increment_deg`] (m).
    pub max_final_increment_m: f64,
    /// Largest standard deviation of a held rotation's angle (deg) for a
    /// frame to count as `tracking` ([`crate::held_axes`]): 1°, the 3°
    /// tracking goal as 3σ (an angle, the same for every target).
    pub max_held_sigma_deg: f64,
    /// Largest turn (deg) of the target, at the predicted rate, between a
    /// frame's mean return time and its end, for a frame of a rigid mode
    /// (`ndt`, `icp`: one pose fitted to the whole scan, seed 000 Fig. 2)
    /// to count as `tracking`. Such a fit is the pose of about the mean
    /// return time, published as the scan end's, so it lags by that turn
    /// ([`crate::assess::rigid_lag_doubt`]). 1°, as
    /// [`Self::max_held_sigma_deg`]: an angle, the same for every target.
    /// `deblur` and `ct-ndt` compensate the motion and are not checked.
    pub max_rigid_lag_deg: f64,
    /// Degraded frames in a row after which the track is declared lost.
    pub max_consecutive_degraded: u32,
    /// The attitude innovation limit that follows the track once its rate
    /// is known: a multiple of its recent innovations, between a floor and
    /// `max_innovation_rot_deg` ([`crate::innovation`]).
    pub innovation: InnovationLimitConfig,
}

impl Default for LossConfig {
    fn default() -> Self {
        Self {
            min_points: 20,
            min_inliers: 100,
            min_inlier_fraction: None,
            max_mean_cost_ndt: None,
            max_mean_cost_icp_m2: 0.002,
            max_innovation_rot_deg: 15.0,
            max_innovation_pos_m: 0.3,
            max_final_increment_deg: 1.0,
            max_final_increment_m: 0.05,
            max_held_sigma_deg: 1.0,
            max_rigid_lag_deg: 1.0,
            max_consecutive_degraded: 5,
            innovation: InnovationLimitConfig::default(),
        }
    }
}

impl LossConfig {
    /// This configuration with its unset target-dependent keys taken from
    /// `thresholds` (what [`crate::Tracker::new`] runs on).
    pub fn resolved(&self, thresholds: &crate::model::TargetThresholds) -> LossConfig {
        LossConfig {
            min_inlier_fraction: self
                .min_inlier_fraction
                .or(Some(thresholds.min_inlier_fraction)),
            max_mean_cost_ndt: self
                .max_mean_cost_ndt
                .or(Some(thresholds.max_mean_cost_ndt)),
            ..self.clone()
        }
    }

    /// The mean-cost bound in force: set or resolved, else the uncalibrated
    /// value (only a configuration never passed through [`Self::resolved`]).
    pub(crate) fn mean_cost_bound_ndt(&self) -> f64 {
        self.max_mean_cost_ndt
            .unwrap_or(crate::model::TargetThresholds::UNCALIBRATED.max_mean_cost_ndt)
    }

    /// The inlier-fraction bound in force (see [`Self::mean_cost_bound_ndt`]).
    pub(crate) fn inlier_fraction_bound(&self) -> f64 {
        self.min_inlier_fraction
            .unwrap_or(crate::model::TargetThresholds::UNCALIBRATED.min_inlier_fraction)
    }

    /// Checks every value; NaN fails (the `loss.*` part of
    /// [`TrackerConfig::validate`](crate::TrackerConfig::validate)).
    pub(crate) fn validate(&self) -> Result<(), TrackError> {
        let bad = |what: &str, v: f64| TrackError::InvalidConfig(format!("{what} = {v}"));
        let l = self;
        let positive = [
            ("loss.max_mean_cost_icp_m2", l.max_mean_cost_icp_m2),
            ("loss.max_innovation_rot_deg", l.max_innovation_rot_deg),
            ("loss.max_innovation_pos_m", l.max_innovation_pos_m),
            ("loss.max_final_increment_deg", l.max_final_increment_deg),
            ("loss.max_final_increment_m", l.max_final_increment_m),
            ("loss.max_held_sigma_deg", l.max_held_sigma_deg),
            ("loss.max_rigid_lag_deg", l.max_rigid_lag_deg),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(&format!("{name} must be finite and > 0"), v));
            }
        }
        if let Some(c) = l.max_mean_cost_ndt
            && !(c.is_finite() && c > 0.0)
        {
            return Err(bad("loss.max_mean_cost_ndt must be finite and > 0", c));
        }
        if let Some(f) = l.min_inlier_fraction
            && !(f.is_finite() && (0.0..=1.0).contains(&f))
        {
            return Err(bad("loss.min_inlier_fraction must be in [0, 1]", f));
        }
        if l.min_points == 0 {
            return Err(TrackError::InvalidConfig(
                "loss.min_points must be >= 1".into(),
            ));
        }
        if l.max_consecutive_degraded == 0 {
            return Err(TrackError::InvalidConfig(
                "loss.max_consecutive_degraded must be >= 1".into(),
            ));
        }
        match l.innovation.problem() {
            Some(p) => Err(TrackError::InvalidConfig(p)),
            None => Ok(()),
        }
    }
}
