//! Assessment of one registration: the reasons to doubt it on its own
//! figures and against the prediction, and what is published for it.
//! Loss is reported, never hidden: a doubted frame is `degraded` and not
//! fused; too many in a row make the track `lost` (`crate::Tracker`).

use crate::config::{LossConfig, TrackerConfig};
use crate::dispatch::{attitude_scaling, ct_attitude_scale};
use crate::held_axes::HeldAxes;
use crate::mode::TrackingMode;
use crate::status::TrackStatus;
use nalgebra::Matrix6;
use spacepose_filter::Prediction;
use spacepose_geometry::Pose;
use spacepose_registration::Registration;

/// A registration that stopped at its iteration limit while still moving
/// by more than `loss.max_final_increment_*`.
pub(crate) fn stalled(l: &LossConfig, r: &Registration) -> bool {
    !r.converged
        && (r.last_increment.rotation_rad.to_degrees() > l.max_final_increment_deg
            || r.last_increment.translation_m > l.max_final_increment_m)
}

/// Reasons to doubt a registration on its own figures.
pub(crate) fn quality_issues(c: &TrackerConfig, r: &Registration) -> Vec<String> {
    let l = &c.loss;
    let mut reasons = Vec::new();
    if r.inliers < l.min_inliers || r.inlier_fraction() < l.inlier_fraction_bound() {
        reasons.push(format!(
            "{} inliers ({:.0}%)",
            r.inliers,
            100.0 * r.inlier_fraction()
        ));
    }
    let max_cost = if c.mode == TrackingMode::Icp {
        l.max_mean_cost_icp_m2
    } else {
        l.mean_cost_bound_ndt()
    };
    if r.cost.mean.is_nan() || r.cost.mean > max_cost {
        reasons.push(format!(
            "mean cost {:.3e} above {max_cost:.3e}",
            r.cost.mean
        ));
    }
    if stalled(l, r) {
        reasons.push(format!(
            "no convergence after {} iterations (last step {:.2} deg, {:.3} m)",
            r.iterations,
            r.last_increment.rotation_rad.to_degrees(),
            r.last_increment.translation_m
        ));
    }
    reasons
}

/// The reason to doubt a measurement that jumps from the prediction by
/// more than `limit_rot_deg` (the track's limit, [`crate::innovation`]) or
/// `loss.max_innovation_pos_m`.
pub(crate) fn inconsistency(
    l: &LossConfig,
    limit_rot_deg: f64,
    innovation_rot_deg: f64,
    innovation_pos_m: f64,
) -> Option<String> {
    (innovation_rot_deg > limit_rot_deg || innovation_pos_m > l.max_innovation_pos_m).then(|| {
        format!(
            "inconsistent with prediction ({innovation_rot_deg:.1} deg, {innovation_pos_m:.3} m; \
             limits {limit_rot_deg:.1} deg, {:.3} m)",
            l.max_innovation_pos_m
        )
    })
}

/// The reason to doubt a frame whose held rotation is more uncertain than
/// `loss.max_held_sigma_deg`, or whose held translation is, as an angle
/// seen from the sensor ([`crate::held_axes`]).
pub(crate) fn held_doubt(l: &LossConfig, held: Option<&HeldAxes>) -> Option<String> {
    let h = held?;
    let sigma_deg = h.sigma_rad.to_degrees();
    let bearing_deg = if h.translations > 0 {
        h.sigma_bearing_rad().to_degrees()
    } else {
        0.0
    };
    let limit = l.max_held_sigma_deg;
    let mut parts = Vec::new();
    if sigma_deg > limit {
        parts.push(format!(
            "{} rotation(s) held with σ {sigma_deg:.1} deg (limit {limit:.1} deg)",
            h.count
        ));
    }
    if bearing_deg > limit {
        parts.push(format!(
            "{} translation(s) held with σ {:.2} m, {bearing_deg:.1} deg seen from the sensor \
             (limit {limit:.1} deg)",
            h.translations, h.sigma_m
        ));
    }
    (!parts.is_empty()).then(|| parts.join("; "))
}

/// The reason to doubt a fit of a rigid mode (`ndt`, `icp`: one pose for
/// the whole uncompensated scan) that lags the scan's end by more than
/// `loss.max_rigid_lag_deg` (the target's turn at the predicted rate since
/// the points' mean acquisition time; `None`: not a rigid fit). Seed 000
/// §3.2 motivates deblurring with this smear. Measured on deos' 10°/s
/// tumble (development seed 2001, `icp`, from the truth): the lagging fits,
/// fused, taught the filter a rate 3.4°/s short, and frames 2-7 went out
/// `tracking` 12-29° off.
pub(crate) fn rigid_lag_doubt(
    l: &LossConfig,
    mode: TrackingMode,
    rigid_lag_deg: Option<f64>,
) -> Option<String> {
    let lag_deg = rigid_lag_deg?;
    (lag_deg > l.max_rigid_lag_deg).then(|| {
        format!(
            "the target turns {lag_deg:.1} deg between the mean return time and the scan's end \
             (limit {:.1} deg), which a {mode} fit of the whole scan cannot follow: use deblur \
             or ct-ndt",
            l.max_rigid_lag_deg
        )
    })
}

/// The measurement covariance `[rot; trans]` with its attitude inflated by
/// `ct_ndt_attitude_covariance_scale` in `ct-ndt` mode (`D C D`,
/// `D = diag(√s I, I)`), unless the cloud was `compensated`: a sparse
/// `ct-ndt` frame fitted as one pose is fused as `deblur` fuses it, since
/// the inflation is for CT-NDT's extrapolated end pose (with it, the filter
/// lost seed 1's tumble in a sparse stretch, its rate hardly corrected).
pub(crate) fn attitude_scaled(
    c: &TrackerConfig,
    mode: TrackingMode,
    covariance: Matrix6<f64>,
    compensated: bool,
) -> Matrix6<f64> {
    if compensated {
        return covariance;
    }
    let d = attitude_scaling(ct_attitude_scale(c, mode));
    d * covariance * d
}

/// The pose (and its covariance) the tracker publishes for a frame: the
/// measurement, unless it was doubted (not fused) in a mode whose estimator
/// is the filter (`deblur`, `ct-ndt`: its prediction seeds every frame).
/// There the filter's prediction stands, as it does for a frame without a
/// measurement: a rejected measurement is not the estimate (tumbling seed
/// 13, frame 84: a stalled fit 3.70° off, the prediction 0.58°). In `ndt`
/// and `icp` modes (Fig. 2) the registration is the estimate and the next
/// guess, so a doubted one is published as it is, flagged by the status.
pub(crate) fn published(
    mode: TrackingMode,
    status: TrackStatus,
    measured: Pose,
    covariance: Option<Matrix6<f64>>,
    prediction: &Prediction,
) -> (Pose, Option<Matrix6<f64>>) {
    if status == TrackStatus::Tracking || !mode.uses_prediction() {
        (measured, covariance)
    } else {
        (prediction.pose, Some(prediction.covariance))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rigid_fit_is_doubted_when_it_lags_beyond_the_limit() {
        let l = LossConfig::default();
        let limit = l.max_rigid_lag_deg;
        assert!(rigid_lag_doubt(&l, TrackingMode::Icp, None).is_none());
        assert!(rigid_lag_doubt(&l, TrackingMode::Icp, Some(0.9 * limit)).is_none());
        let reason = rigid_lag_doubt(&l, TrackingMode::Ndt, Some(2.5 * limit)).unwrap();
        assert!(reason.contains("ndt fit"), "{reason}");
        assert!(
            reason.contains(&format!("{:.1} deg", 2.5 * limit)),
            "{reason}"
        );
    }
}
