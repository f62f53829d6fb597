//! The Gauss-Newton loop on SE(3) shared by NDT and CT-NDT (seed 000 §3.1):
//! linearise, solve Eq. (7), update `T ← ε ⊕ T` (Eq. 5), stop on a small
//! increment (Table 1), then evaluate once more at the returned pose.

use crate::error::RegistrationError;
use crate::normal_equations::{NormalEquations, increment_of};
use crate::params::NdtParams;
use crate::result::{Cost, Increment, Registration};
use spacepose_geometry::Pose;

/// Runs Gauss-Newton from `initial`. `linearise(T)` returns the normal
/// equations at `T`; the function never allocates per iteration itself.
///
/// The returned cost, inliers and information are those of a final
/// evaluation at the returned pose (one extra association pass), so they
/// describe the estimate itself rather than the previous iterate.
pub(crate) fn run(
    initial: Pose,
    params: &NdtParams,
    valid_points: usize,
    skipped_non_finite: usize,
    mut linearise: impl FnMut(&Pose) -> NormalEquations,
) -> Result<Registration, RegistrationError> {
    let no_match = |iteration| RegistrationError::NoCorrespondences {
        iteration,
        max_distance_m: params.max_distance_m,
    };
    let rot_tol = params.termination_rotation_deg.to_radians();
    let mut pose = initial;
    let mut converged = false;
    let mut iterations = 0;
    let mut last = Increment::default();
    for it in 0..params.max_iterations {
        let ne = linearise(&pose);
        if ne.inliers == 0 {
            return Err(no_match(it));
        }
        let eps = ne.solve(it)?;
        pose = pose.oplus(&eps); // T ← ε ⊕ T, Eq. (5)
        iterations = it + 1;
        last = increment_of(&eps);
        if last.rotation_rad < rot_tol && last.translation_m < params.termination_translation_m {
            converged = true;
            break;
        }
    }
    let ne = linearise(&pose);
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
    })
}
