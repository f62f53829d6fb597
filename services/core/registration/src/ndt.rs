//! Smoothed NDT registration, seed 000 §3.1: Gauss-Newton on SE(3) of the
//! relaxed cost of Eq. (3) with the left Jacobian of Eq. (6) and the
//! increment of Eq. (7).

use crate::error::RegistrationError;
use crate::gauss_newton;
use crate::ndt_map::NdtMap;
use crate::normal_equations::{Constrained, NormalEquations};
use crate::params::NdtParams;
use crate::result::Registration;
use crate::source::{check_pose, finite_positions};
use nalgebra::{Matrix6, Vector3};
use spacepose_geometry::{Point, Pose};

/// Normal equations of Eq. (7) at `t` over every `stride`-th point: each point `z_i` is associated with
/// the cell whose smoothed mean is nearest to `T(z_i)` when that mean is
/// within `max_distance_m` (η of Eq. 3), and contributes
/// `Jᵢᵀ C⁻¹ Jᵢ` and `Jᵢᵀ C⁻¹ (T(zᵢ) - μ)` with `Jᵢ = [-(R zᵢ)^×  I₃]`.
pub(crate) fn linearise(
    map: &NdtMap,
    points: &[Vector3<f64>],
    t: &Pose,
    stride: usize,
    params: &NdtParams,
) -> NormalEquations {
    let rotation = t.rotation.matrix();
    let mut ne = NormalEquations::new();
    for z in points.iter().step_by(stride.max(1)) {
        let rz = rotation * z;
        let x = rz + t.translation;
        if let Some((k, _)) = map.nearest_cell(&x, params.max_distance_m, params.lookup) {
            let (mean, information) = map.mean_and_information(k);
            ne.add_rigid(&rz, information, &(x - mean));
        }
    }
    ne
}

/// The geometric information at `t` over every `stride`-th point: each
/// associated point adds `Jᵀ n nᵀ J` with `n` its cell's normal (what the
/// surface constrains; see `NdtParams::degeneracy_ratio`).
pub(crate) fn geometric_information(
    map: &NdtMap,
    points: &[Vector3<f64>],
    t: &Pose,
    stride: usize,
    params: &NdtParams,
) -> (Matrix6<f64>, usize) {
    let rotation = t.rotation.matrix();
    let mut ne = NormalEquations::new();
    for z in points.iter().step_by(stride.max(1)) {
        let rz = rotation * z;
        let x = rz + t.translation;
        if let Some((k, _)) = map.nearest_cell(&x, params.max_distance_m, params.lookup) {
            let (mean, n) = map.mean_and_normal(k);
            ne.add_rigid(&rz, &(n * n.transpose()), &(x - mean));
        }
    }
    (ne.hessian(), ne.inliers)
}

/// Registers `source` (sensor frame) against the smoothed NDT `map`
/// (target body frame), starting from `initial_t_target_sensor`.
///
/// Gauss-Newton (Eq. 7) with `T ← ε ⊕ T` (Eq. 5) until the increment is
/// below both termination thresholds or `max_iterations` is reached
/// (`converged` tells which). Non-finite points are skipped and counted.
///
/// Errors: invalid parameters or a non-finite initial pose; an empty cloud;
/// a cloud with no finite point; no correspondence at some iterate
/// ([`RegistrationError::NoCorrespondences`]); normal equations that are
/// not positive definite ([`RegistrationError::DegenerateSystem`]).
pub fn register_ndt(
    map: &NdtMap,
    source: &[Point],
    initial_t_target_sensor: &Pose,
    params: &NdtParams,
) -> Result<Registration, RegistrationError> {
    params.validate()?;
    check_pose("initial_t_target_sensor", initial_t_target_sensor)?;
    let (points, skipped) = finite_positions(source)?;
    let constrained = params
        .handles_degeneracy()
        .then(|| {
            let (h, n) = geometric_information(map, &points, initial_t_target_sensor, 1, params);
            Constrained::of(&h, n, params.min_lever_arm_m, params.min_translation_cosine)
        })
        .flatten();
    gauss_newton::run(
        *initial_t_target_sensor,
        params,
        points.len(),
        skipped,
        constrained.as_ref(),
        |t, stride| linearise(map, &points, t, stride, params),
    )
}

#[cfg(test)]
mod tests;

#[cfg(test)]
#[path = "ndt/degeneracy_tests.rs"]
pub(crate) mod degeneracy_tests;
