//! A held rotation's uncertainty, in the covariance and the status (issue
//! 25 item 4; not in seed 000, whose NDT has no degeneracy handling).
//!
//! Where the surface in view leaves a rotation free, every mode holds it
//! at the filter's prediction (`NdtParams::min_lever_arm_m`, the ICP
//! equivalent), or on the line fitted before the hold
//! ([`crate::held_rotation`]). That angle is an extrapolation, not a
//! measurement, yet the registration's information still claims the few
//! millimetres of lever arm the surface gave it: plain `ndt` on the
//! tumbling deos published 10° more error every frame as `tracking`, with
//! the covariance of a fit (issue 25: 534 such frames on 21 blind seeds).
//!
//! Here the held turn `u = [a; −H_tt⁻¹ H_tr a]` (the rotation about the
//! held axis `a` with the translation that keeps the surface fitted, in the
//! `δ` of `t_target_sensor`) gets the extrapolation's variance `σ²`:
//! - on the fitted line, the line's own (its least-squares `σ` at the
//!   frame's time), an independent estimate the filter may fuse;
//! - otherwise the prediction's variance about `a` plus the squared turn
//!   between the result and the prediction about `a`. That is the filter's
//!   own knowledge, so what the filter fuses carries
//!   [`NO_INFORMATION`] times it: nothing, and the filter's covariance
//!   about `a` grows as a prediction's does instead of shrinking on its
//!   own echo.
//!
//! The published covariance is the registration's plus `σ² u uᵀ`. A frame
//! whose held `σ` is above `loss.max_held_sigma_deg` is doubted like any
//! other (`degraded`, not fused; `lost` after
//! `loss.max_consecutive_degraded` in a row): its attitude cannot be
//! vouched for. The default, 1°, is the tracking goal (3°) as 3σ: an
//! angle, so it does not depend on the target's size.

use crate::measurement::inversion_jacobian;
use nalgebra::{Matrix6, Vector3, Vector6};
use spacepose_filter::Prediction;
use spacepose_geometry::{Pose, so3};
use spacepose_registration::Registration;

/// The factor on a held rotation's variance in what the filter fuses when
/// that variance is the prediction's own: large enough that the fused
/// measurement adds nothing about the held angle.
pub const NO_INFORMATION: f64 = 1e4;

/// The rotations a registration held and how uncertain they are.
#[derive(Debug, Clone, PartialEq)]
pub struct HeldAxes {
    /// Rotations held (the registration's `degenerate_directions`).
    pub count: usize,
    /// Standard deviation of the held angle (rad); the largest over the
    /// held axes.
    pub sigma_rad: f64,
    /// The held turns `u` (`δ = [rot; trans]` of `t_target_sensor`, per
    /// radian about each held axis).
    turns: Vec<Vector6<f64>>,
    /// `sigma_rad` is the fitted line's (independent of the filter).
    from_line: bool,
}

impl HeldAxes {
    /// The held rotations of `registration` (the result as published, at
    /// `prediction`'s time), or `None` when it held none. `line_sigma_rad`
    /// is the fitted line's σ (`crate::HeldCorrection::sigma_rad`), when
    /// the hold followed one.
    pub fn of(
        registration: &Registration,
        line_sigma_rad: Option<f64>,
        prediction: &Prediction,
    ) -> Option<HeldAxes> {
        let count = registration.degenerate_directions;
        if count == 0 {
            return None;
        }
        let h = registration
            .geometric_information
            .unwrap_or(registration.information);
        let axes = weakest_rotations(&h, count.min(3));
        let turns: Vec<Vector6<f64>> = axes.iter().map(|a| held_turn(&h, a)).collect();
        let t_ts = &registration.t_target_sensor;
        // The line follows one held rotation only.
        let line_sigma_rad = line_sigma_rad.filter(|_| count == 1);
        let sigma_rad = line_sigma_rad.unwrap_or_else(|| {
            axes.iter()
                .map(|a| predicted_sigma(t_ts, a, prediction))
                .fold(0.0, f64::max)
        });
        Some(HeldAxes {
            count,
            sigma_rad,
            from_line: line_sigma_rad.is_some(),
            turns,
        })
    }

    /// `covariance` (of `t_sensor_target`, left ⊕) with the held turns'
    /// variance added, as `(fused, published)`: what the filter may fuse
    /// (the line's variance, or [`NO_INFORMATION`] times the
    /// prediction's), and what is published (`σ²`).
    pub fn covariances(
        &self,
        t_target_sensor: &Pose,
        covariance: &Matrix6<f64>,
    ) -> (Matrix6<f64>, Matrix6<f64>) {
        let var = self.sigma_rad.powi(2);
        // A held angle the prediction knows exactly still gets no weight.
        let fused_var = if self.from_line {
            var
        } else {
            (var * NO_INFORMATION).max(1.0)
        };
        let a = inversion_jacobian(t_target_sensor);
        let (mut fused, mut published) = (*covariance, *covariance);
        for u in &self.turns {
            let xi = a * u;
            let outer = xi * xi.transpose();
            fused += outer * fused_var;
            published += outer * var;
        }
        (fused, published)
    }
}

/// The `k` rotation axes (target frame, unit) the information `h`
/// (`δ = [rot; trans]`) constrains least once the translation is
/// marginalised out, weakest first; fewer when `h` is not usable.
pub(crate) fn weakest_rotations(h: &Matrix6<f64>, k: usize) -> Vec<Vector3<f64>> {
    let h_rr = h.fixed_view::<3, 3>(0, 0).into_owned();
    let h_rt = h.fixed_view::<3, 3>(0, 3).into_owned();
    let Some(h_tt_inv) = h.fixed_view::<3, 3>(3, 3).into_owned().try_inverse() else {
        return Vec::new();
    };
    let schur = h_rr - h_rt * h_tt_inv * h_rt.transpose();
    let eig = ((schur + schur.transpose()) * 0.5).symmetric_eigen();
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    order
        .iter()
        .take(k)
        .map(|&i| eig.eigenvectors.column(i).into_owned())
        .filter(|v: &Vector3<f64>| v.iter().all(|x| x.is_finite()))
        .collect()
}

/// The turn about `axis` with the translation that keeps the surface
/// fitted (`−H_tt⁻¹ H_tr a`, the Schur complement's), per radian.
pub(crate) fn held_turn(h: &Matrix6<f64>, axis: &Vector3<f64>) -> Vector6<f64> {
    let h_tt = h.fixed_view::<3, 3>(3, 3).into_owned();
    let h_tr = h.fixed_view::<3, 3>(3, 0).into_owned();
    let shift = h_tt
        .try_inverse()
        .map_or(Vector3::zeros(), |inv| -(inv * h_tr * axis));
    Vector6::new(axis.x, axis.y, axis.z, shift.x, shift.y, shift.z)
}

/// `σ` (rad) of the angle about `axis` (target frame) of a result held at
/// the prediction: the prediction's standard deviation about it (its
/// covariance is that of `t_sensor_target`'s left ⊕, rotation in the
/// sensor frame: `ξ_rot = −R_st δ_rot`) and the turn from the prediction
/// about it, in quadrature.
fn predicted_sigma(t_target_sensor: &Pose, axis: &Vector3<f64>, prediction: &Prediction) -> f64 {
    let r_st = t_target_sensor.rotation.inverse();
    let a_sensor = r_st * axis;
    let p_rr = prediction.covariance.fixed_view::<3, 3>(0, 0).into_owned();
    let var = (a_sensor.transpose() * p_rr * a_sensor)[(0, 0)].max(0.0);
    let r_ts_predicted = prediction.pose.rotation.inverse();
    let turn = so3::log(&(t_target_sensor.rotation * r_ts_predicted.inverse())).dot(axis);
    (var + turn * turn).sqrt()
}

#[cfg(test)]
#[path = "held_axes_tests.rs"]
mod tests;
