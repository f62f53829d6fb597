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
use spacepose_registration::weak_directions::Held;

/// The factor on a held direction's variance in what the filter fuses when
/// that variance is the prediction's own: large enough that the fused
/// measurement adds nothing about the held angle or shift.
pub const NO_INFORMATION: f64 = 1e4;

/// The rotations and translations a registration held and how uncertain
/// they are.
#[derive(Debug, Clone, PartialEq)]
pub struct HeldAxes {
    /// Rotations held (the registration's `degenerate_directions`).
    pub count: usize,
    /// Translations held (the registration's `held_translations`).
    pub translations: usize,
    /// Standard deviation of the held angle (rad); the largest over the
    /// held axes, 0 when no rotation is held.
    pub sigma_rad: f64,
    /// Standard deviation of the held shift (m); the largest over the held
    /// translations, 0 when none is held.
    pub sigma_m: f64,
    /// The sensor's distance to the target origin (m), which turns
    /// `sigma_m` into an angle seen from the sensor.
    pub range_m: f64,
    /// The held turns `u` (`δ = [rot; trans]` of `t_target_sensor`, per
    /// radian about each held axis), then the held shifts (per metre).
    moves: Vec<Vector6<f64>>,
    /// `sigma_rad` is the fitted line's (independent of the filter).
    from_line: bool,
}

impl HeldAxes {
    /// The held directions of `registration` (the result as published, at
    /// `prediction`'s time), or `None` when it held none. `line_sigma_rad`
    /// is the fitted line's σ (`crate::HeldCorrection::sigma_rad`), when
    /// the hold followed one.
    pub fn of(
        registration: &Registration,
        line_sigma_rad: Option<f64>,
        prediction: &Prediction,
    ) -> Option<HeldAxes> {
        let (count, translations) = (
            registration.degenerate_directions.min(3),
            registration.held_translations.min(3),
        );
        if count + translations == 0 {
            return None;
        }
        let h = registration
            .geometric_information
            .unwrap_or(registration.information);
        let held = Held::of(&h, count, translations);
        let t_ts = &registration.t_target_sensor;
        // The line follows one held rotation only.
        let line_sigma_rad = line_sigma_rad.filter(|_| count == 1);
        let sigma_rad = line_sigma_rad.unwrap_or_else(|| {
            held.rotations
                .iter()
                .map(|a| predicted_sigma(t_ts, a, prediction))
                .fold(0.0, f64::max)
        });
        let sigma_m = held
            .translations
            .iter()
            .map(|d| predicted_shift_sigma(t_ts, d, prediction))
            .fold(0.0, f64::max);
        Some(HeldAxes {
            count: held.rotations.len(),
            translations: held.translations.len(),
            sigma_rad,
            sigma_m,
            range_m: t_ts.translation.norm(),
            from_line: line_sigma_rad.is_some(),
            moves: held.moves(&h),
        })
    }

    /// The held moves (`δ = [rot; trans]` of `t_target_sensor`): each held
    /// rotation's turn per radian, then each held translation's shift per
    /// metre.
    pub fn moves(&self) -> &[Vector6<f64>] {
        &self.moves
    }

    /// `sigma_m` as an angle seen from the sensor (rad).
    pub fn sigma_bearing_rad(&self) -> f64 {
        if self.range_m > 0.0 {
            (self.sigma_m / self.range_m).atan()
        } else {
            f64::INFINITY
        }
    }

    /// `covariance` (of `t_sensor_target`, left ⊕) with the held moves'
    /// variance added, as `(fused, published)`: what the filter may fuse
    /// (the line's variance, or [`NO_INFORMATION`] times the
    /// prediction's), and what is published (`σ²`).
    pub fn covariances(
        &self,
        t_target_sensor: &Pose,
        covariance: &Matrix6<f64>,
    ) -> (Matrix6<f64>, Matrix6<f64>) {
        let nothing = |var: f64| (var * NO_INFORMATION).max(1.0);
        let rot_var = self.sigma_rad.powi(2);
        // A held angle the prediction knows exactly still gets no weight.
        let rot_fused = if self.from_line {
            rot_var
        } else {
            nothing(rot_var)
        };
        let shift_var = self.sigma_m.powi(2);
        let a = inversion_jacobian(t_target_sensor);
        let (mut fused, mut published) = (*covariance, *covariance);
        for (i, u) in self.moves.iter().enumerate() {
            let (var, fused_var) = if i < self.count {
                (rot_var, rot_fused)
            } else {
                (shift_var, nothing(shift_var))
            };
            let xi = a * u;
            let outer = xi * xi.transpose();
            fused += outer * fused_var;
            published += outer * var;
        }
        (fused, published)
    }
}

/// `σ` (m) of the shift along `axis` (target frame, the translation of
/// `t_target_sensor`'s `δ`) of a result held at the prediction: the
/// prediction's standard deviation along it and the shift from the
/// prediction along it, in quadrature.
///
/// The marginal variance, which at 15 m is mostly the attitude's
/// uncertainty times the range (the `δ` translation is the sensor's
/// position in the target frame). The variance conditional on the other
/// coordinates (`1 / (eᵀ Λ e)`) was tried: it is centimetres, so held
/// frames stayed `tracking` while the filter, dragged by the frames just
/// above the threshold, carried the hold 88 cm off (`zoo:1003` slow-spin,
/// development seed 2023: 19-22 frames far off published `tracking`
/// instead of 2). See `docs/design/held-translations.md`.
fn predicted_shift_sigma(
    t_target_sensor: &Pose,
    axis: &Vector3<f64>,
    prediction: &Prediction,
) -> f64 {
    let predicted = prediction.pose.inverse();
    let e = Vector6::new(0.0, 0.0, 0.0, axis.x, axis.y, axis.z);
    // δ = A⁻¹ ξ: the prediction's covariance in the `δ` of t_target_sensor.
    let var = inversion_jacobian(&predicted)
        .try_inverse()
        .map_or(f64::INFINITY, |b| {
            (e.transpose() * b * prediction.covariance * b.transpose() * e)[(0, 0)].max(0.0)
        });
    let shift = axis.dot(&t_target_sensor.ominus(&predicted).fixed_rows::<3>(3));
    (var + shift * shift).sqrt()
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
