//! NDT's degeneracy handling (`NdtParams::min_lever_arm_m`,
//! `NdtParams::min_translation_cosine`) for a
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
use crate::weak_directions::Held;
use nalgebra::{Matrix6, Vector3};
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
    if !params.handles_degeneracy() {
        return None;
    }
    let positions: Vec<Vector3<f64>> = source
        .iter()
        .filter(|p| position_is_finite(p) && p.t.is_finite())
        .map(Point::position)
        .collect();
    let (h, n) = geometric_information(map, &positions, t_target_sensor, 1, params);
    Constrained::of(&h, n, params.min_lever_arm_m, params.min_translation_cosine)
}

/// Applies NDT's degeneracy handling to `registration`, a result fitted by
/// a method without it (ICP), holding the directions the surface leaves
/// free at `reference_t_target_sensor`: the registration's own guess, as
/// [`crate::register_ndt`] holds them, or a prediction.
///
/// The directions come from the surface seen from the reference pose
/// ([`crate::weak_directions`]). Each rotation whose lever arm is below
/// `params.min_lever_arm_m` is held: its component of `registration ⊖
/// reference` is removed together with the translation that goes with it,
/// which leaves the surface fitted. Then each translation whose cosine is
/// below `params.min_translation_cosine` is held the same way, with the
/// turn of the kept rotations that goes with it. The result then carries
/// `degenerate_directions`, `held_translations`, the weakest figures and
/// `geometric_information` as NDT's would; everything else (cost,
/// inliers, information, iterations) is the registration's own.
///
/// Returns `registration` unchanged when the handling is disabled or the
/// surface's information is unusable.
pub fn hold_weak_directions(
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
    let h = &c.information;
    if c.dropped() + c.held_translations() > 0 {
        registration.t_target_sensor =
            held_at(&c.held, h, &registration.t_target_sensor, reference);
    }
    registration.degenerate_directions = c.dropped();
    registration.held_translations = c.held_translations();
    registration.weakest_lever_arm_m = c.weakest_lever_arm_m;
    registration.weakest_translation_cosine = c.weakest_translation_cosine;
    registration.geometric_information = Some(c.information);
    registration
}

/// `t_target_sensor` with its `held` directions moved to those of
/// `reference`.
fn held_at(held: &Held, h: &Matrix6<f64>, t_target_sensor: &Pose, reference: &Pose) -> Pose {
    let mut eps = t_target_sensor.ominus(reference);
    let moves = held.moves(h);
    let (turns, shifts) = moves.split_at(held.rotations.len());
    // Rotations first: their shifts may move a held translation, whose
    // turns lie in the kept rotations only.
    for (axis, turn) in held.rotations.iter().zip(turns) {
        eps -= turn * axis.dot(&eps.fixed_rows::<3>(0));
    }
    for (axis, shift) in held.translations.iter().zip(shifts) {
        eps -= shift * axis.dot(&eps.fixed_rows::<3>(3));
    }
    reference.oplus(&eps)
}

#[cfg(test)]
#[path = "degeneracy_tests.rs"]
mod tests;
