//! NDT's degeneracy handling (`NdtParams::min_lever_arm_m`) for a
//! registration that has none of its own: point-to-point ICP.
//!
//! ICP's Hessian is that of the points, not of the surface, so it never
//! looks degenerate; yet where the surface in view leaves a rotation free
//! (deos end-on at the 3 m hold: the roll about the tower), the nearest
//! neighbours do not pull along it, and ICP holds that rotation at its
//! guess without saying so. Here the surface's geometric information (the
//! smoothed NDT map's cell normals) finds such rotations, and the
//! registration is reported as NDT reports a held rotation, so that a
//! tracker can treat both alike.

use crate::ndt::geometric_information;
use crate::ndt_map::NdtMap;
use crate::normal_equations::Constrained;
use crate::params::NdtParams;
use crate::result::Registration;
use crate::source::position_is_finite;
use nalgebra::{Matrix3, Vector3, Vector6};
use spacepose_geometry::{Point, Pose};

/// The well-constrained directions of the surface seen by `source` placed
/// at `t_target_sensor`; `None` when disabled (`min_lever_arm_m` ≤ 0), or
/// without any finite point or a usable information matrix.
pub(crate) fn constrained_directions(
    map: &NdtMap,
    source: &[Point],
    t_target_sensor: &Pose,
    params: &NdtParams,
) -> Option<Constrained> {
    if params.min_lever_arm_m <= 0.0 {
        return None;
    }
    let positions: Vec<Vector3<f64>> = source
        .iter()
        .filter(|p| position_is_finite(p) && p.t.is_finite())
        .map(Point::position)
        .collect();
    let (h, n) = geometric_information(map, &positions, t_target_sensor, 1, params);
    Constrained::of(&h, n, params.min_lever_arm_m)
}

/// Applies NDT's degeneracy handling to `registration`, a result fitted by
/// a method without it (ICP), holding the rotations the surface leaves
/// free at `reference_t_target_sensor`: the registration's own guess, as
/// [`crate::register_ndt`] holds them, or a prediction.
///
/// The directions come from the surface seen from the reference pose.
/// Each rotation whose lever arm is below `params.min_lever_arm_m` is
/// held: its component of `registration ⊖ reference` is removed together
/// with the translation that goes with it (the geometric information's
/// Schur complement, `−H_tt⁻¹ H_tr a` per unit turn about `a`), which
/// leaves the surface fitted. The result then carries
/// `degenerate_directions`, `weakest_lever_arm_m` and
/// `geometric_information` as NDT's would; everything else (cost,
/// inliers, information, iterations) is the registration's own.
///
/// Returns `registration` unchanged when the handling is disabled or the
/// surface's information is unusable.
pub fn hold_weak_rotations(
    map: &NdtMap,
    source: &[Point],
    reference_t_target_sensor: &Pose,
    mut registration: Registration,
    params: &NdtParams,
) -> Registration {
    let reference = reference_t_target_sensor;
    let Some(c) = constrained_directions(map, source, reference, params) else {
        return registration;
    };
    let kept_rotations: Vec<Vector3<f64>> = c
        .basis
        .iter()
        .filter(|b| b.fixed_rows::<3>(3).norm() == 0.0)
        .map(|b| b.fixed_rows::<3>(0).into_owned())
        .collect();
    if kept_rotations.len() < 3 {
        let h = &c.information;
        let h_tt = h.fixed_view::<3, 3>(3, 3).into_owned();
        let h_tr: Matrix3<f64> = h.fixed_view::<3, 3>(3, 0).into_owned();
        let coupling = h_tt.try_inverse().map(|inv| -(inv * h_tr));
        let mut eps = registration.t_target_sensor.ominus(reference);
        for axis in dropped_axes(&kept_rotations) {
            let turn = axis.dot(&eps.fixed_rows::<3>(0));
            let shift = coupling.map_or(Vector3::zeros(), |k| k * axis);
            eps -= Vector6::new(axis.x, axis.y, axis.z, shift.x, shift.y, shift.z) * turn;
        }
        registration.t_target_sensor = reference.oplus(&eps);
    }
    registration.degenerate_directions = c.dropped();
    registration.weakest_lever_arm_m = c.weakest_lever_arm_m;
    registration.geometric_information = Some(c.information);
    registration
}

/// An orthonormal basis of the rotations orthogonal to `kept` (itself
/// orthonormal, fewer than three).
fn dropped_axes(kept: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    let mut dropped: Vec<Vector3<f64>> = Vec::new();
    for e in [Vector3::x(), Vector3::y(), Vector3::z()] {
        let mut v = e;
        for k in kept.iter().chain(dropped.iter()) {
            v -= k * k.dot(&v);
        }
        if let Some(u) = v.try_normalize(1e-6) {
            dropped.push(u);
        }
        if kept.len() + dropped.len() == 3 {
            break;
        }
    }
    dropped
}

#[cfg(test)]
#[path = "degeneracy_tests.rs"]
mod tests;
