//! The Gauss-Newton loop on SE(3) shared by NDT and CT-NDT (seed 000 §3.1):
//! linearise, solve Eq. (7), update `T ← ε ⊕ T` (Eq. 5), stop on a small
//! increment (Table 1).

use crate::error::RegistrationError;
use crate::normal_equations::{Constrained, NormalEquations, increment_of};
use crate::params::NdtParams;
use crate::result::{Cost, Increment, Registration};
use spacepose_geometry::Pose;

/// Runs Gauss-Newton from `initial`. `linearise(T, stride)` returns the
/// normal equations at `T` over every `stride`-th point; nothing is
/// allocated per iteration.
///
/// Coarse phase (speed, not in the paper): while `params.coarse_stride > 1`
/// the increments are computed on every `coarse_stride`-th point only,
/// until an increment falls below `coarse_switch` times the termination
/// thresholds; all later iterations, and the convergence test, use every
/// point, so the optimum reached is that of the full cloud.
///
/// Cost, inliers and information: when converged, those of the last
/// (full) linearisation, i.e. at the pose before the last increment, which
/// is below the termination thresholds (0.05°, 1 mm by default); otherwise
/// a final evaluation at the returned pose.
///
/// `constrained`: increments restricted to its well-constrained directions
/// (see `NdtParams::min_lever_arm_m`); `None`: the full Eq. (7).
pub(crate) fn run(
    initial: Pose,
    params: &NdtParams,
    valid_points: usize,
    skipped_non_finite: usize,
    constrained: Option<&Constrained>,
    mut linearise: impl FnMut(&Pose, usize) -> NormalEquations,
) -> Result<Registration, RegistrationError> {
    let no_match = |iteration| RegistrationError::NoCorrespondences {
        iteration,
        max_distance_m: params.max_distance_m,
    };
    let rot_tol = params.termination_rotation_deg.to_radians();
    let below = |inc: &Increment, factor: f64| {
        inc.rotation_rad < rot_tol * factor
            && inc.translation_m < params.termination_translation_m * factor
    };
    let mut stride = params.coarse_stride.max(1);
    let mut pose = initial;
    let mut iterations = 0;
    let mut last = Increment::default();
    let mut final_ne = None;
    for it in 0..params.max_iterations {
        let mut ne = linearise(&pose, stride);
        if ne.inliers < 6 && stride > 1 {
            // Too sparse a subset: continue on every point.
            stride = 1;
            ne = linearise(&pose, stride);
        }
        if ne.inliers == 0 {
            return Err(no_match(it));
        }
        let eps = match constrained {
            Some(c) => ne.solve_in(&c.basis, it)?,
            None => ne.solve(it)?,
        };
        pose = pose.oplus(&eps); // T ← ε ⊕ T, Eq. (5)
        iterations = it + 1;
        last = increment_of(&eps);
        if stride == 1 && below(&last, 1.0) {
            final_ne = Some(ne);
            break;
        }
        if stride > 1 && below(&last, params.coarse_switch) {
            stride = 1;
        }
    }
    let converged = final_ne.is_some();
    let ne = match final_ne {
        Some(ne) => ne,
        None => linearise(&pose, 1),
    };
    if ne.inliers == 0 {
        return Err(no_match(iterations));
    }
    let n = ne.inliers as f64;
    Ok(Registration {
        t_target_sensor: pose,
        converged,
        iterations,
        cost: Cost {
            total: ne.cost,
            mean: ne.cost / n,
        },
        inliers: ne.inliers,
        valid_points,
        skipped_non_finite,
        mean_squared_distance_m2: ne.squared_distance / n,
        f_conv_m2: None,
        information: ne.hessian(),
        last_increment: last,
        degenerate_directions: constrained.map_or(0, Constrained::dropped),
        weakest_lever_arm_m: constrained.map_or(f64::NAN, |c| c.weakest_lever_arm_m),
        geometric_information: constrained.map(|c| c.information),
    })
}
