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
    let run = iterate(initial, params, constrained, &mut linearise)?;
    let converged = run.final_ne.is_some();
    let ne = match run.final_ne {
        Some(ne) => ne,
        None => linearise(&run.pose, 1),
    };
    if ne.inliers == 0 {
        return Err(no_match(params, run.iterations));
    }
    let n = ne.inliers as f64;
    Ok(Registration {
        t_target_sensor: run.pose,
        converged,
        iterations: run.iterations,
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
        last_increment: run.last,
        degenerate_directions: constrained.map_or(0, Constrained::dropped),
        weakest_lever_arm_m: constrained.map_or(f64::NAN, |c| c.weakest_lever_arm_m),
        held_translations: constrained.map_or(0, Constrained::held_translations),
        weakest_translation_cosine: constrained.map_or(f64::NAN, |c| c.weakest_translation_cosine),
        geometric_information: constrained.map(|c| c.information),
    })
}

/// Where the Gauss-Newton loop stopped.
struct Iterated {
    /// The last iterate.
    pose: Pose,
    /// Increments applied.
    iterations: usize,
    /// The last increment.
    last: Increment,
    /// The full linearisation whose increment met the termination
    /// thresholds (`None`: the iteration limit was reached).
    final_ne: Option<NormalEquations>,
}

/// The error for an iterate without a single correspondence.
fn no_match(params: &NdtParams, iteration: usize) -> RegistrationError {
    RegistrationError::NoCorrespondences {
        iteration,
        max_distance_m: params.max_distance_m,
    }
}

/// The increment `inc` is below the termination thresholds (Table 1)
/// times `factor`.
fn below(params: &NdtParams, inc: &Increment, factor: f64) -> bool {
    inc.rotation_rad < params.termination_rotation_deg.to_radians() * factor
        && inc.translation_m < params.termination_translation_m * factor
}

/// The Gauss-Newton iterations from `initial`: the coarse phase on every
/// `coarse_stride`-th point, then every point until an increment is below
/// the termination thresholds or `max_iterations` is reached.
fn iterate(
    initial: Pose,
    params: &NdtParams,
    constrained: Option<&Constrained>,
    linearise: &mut impl FnMut(&Pose, usize) -> NormalEquations,
) -> Result<Iterated, RegistrationError> {
    let mut stride = params.coarse_stride.max(1);
    let mut run = Iterated {
        pose: initial,
        iterations: 0,
        last: Increment::default(),
        final_ne: None,
    };
    for it in 0..params.max_iterations {
        let mut ne = linearise(&run.pose, stride);
        if ne.inliers < 6 && stride > 1 {
            // Too sparse a subset: continue on every point.
            stride = 1;
            ne = linearise(&run.pose, stride);
        }
        if ne.inliers == 0 {
            return Err(no_match(params, it));
        }
        let eps = match constrained {
            Some(c) => ne.solve_in(&c.basis, it)?,
            None => ne.solve(it)?,
        };
        run.pose = run.pose.oplus(&eps); // T ← ε ⊕ T, Eq. (5)
        run.iterations = it + 1;
        run.last = increment_of(&eps);
        if stride == 1 && below(params, &run.last, 1.0) {
            run.final_ne = Some(ne);
            break;
        }
        if stride > 1 && below(params, &run.last, params.coarse_switch) {
            stride = 1;
        }
    }
    Ok(run)
}
