//! Continuous-time NDT with a free start pose (a departure from seed 000
//! §3.3, measured in `docs/design/ct-ndt-start-pose.md`).
//!
//! Eq. (14) fixes the start pose `T^s` at the previous result, so an error
//! there moves the early points of the scan for good: they fall outside the
//! 7.5 cm association distance, the end pose bends to fit the rest, and the
//! next scan starts from that. On sparse frames (1-3k points, MLI faces
//! invisible) this fed on itself until track was lost.
//!
//! Here `T^s` and `T^e` are optimised together; `T^s` is held by a Gaussian
//! prior (mean and information, typically the filter's estimate at the scan
//! start), the Maximum-a-posteriori form of the paper's constraint: an
//! infinite prior information gives back Eq. (14). The Jacobian with
//! respect to `T^s` is Eq. (15) with the ends swapped, since
//! `interp(T^s, T^e, u) = interp(T^e, T^s, 1 - u)`.
//!
//! The reported information is that of `T^e` with `T^s` marginalised out
//! (Schur complement), the reported cost that of the points alone.

use super::displacement_prior::DisplacementPrior;
use super::interpolation::ScanTimes;
use super::joint::{Joint, TimedPoint, linearise, split};
use super::rate_prior::RatePrior;
use super::start_prior::StartPrior;
use crate::degeneracy::constrained_directions;
use crate::error::RegistrationError;
use crate::ndt_map::NdtMap;
use crate::normal_equations::{Constrained, increment_of};
use crate::params::NdtParams;
use crate::result::{Cost, Increment, Registration};
use crate::source::{check_pose, position_is_finite};
use nalgebra::DMatrix;
use spacepose_geometry::{Point, Pose};

/// Termination tolerance of the start pose's increment, in multiples of
/// the end pose's thresholds (`termination_rotation_deg`,
/// `termination_translation_m`).
const START_TOLERANCE: f64 = 5.0;

/// The outcome of [`register_ct_ndt_free_start`].
#[derive(Debug, Clone, PartialEq)]
pub struct CtRegistration {
    /// The end pose `T^e` with its quality figures; `information` is that
    /// of `T^e` with `T^s` marginalised out.
    pub end: Registration,
    /// The estimated start pose `T^s`.
    pub t_target_sensor_start: Pose,
    /// How far `T^s` moved from the prior mean.
    pub start_correction: Increment,
}

/// Continuous-time NDT with the start pose free under `prior` (see the
/// module documentation). Termination: [`crate::register_ndt`]'s test on
/// the end pose, with the start pose's increment within `START_TOLERANCE`
/// times the thresholds; no coarse phase (`coarse_stride` is ignored).
/// Same errors as [`super::register_ct_ndt`], plus an invalid prior.
pub fn register_ct_ndt_free_start(
    map: &NdtMap,
    source: &[Point],
    scan: &ScanTimes,
    prior: &StartPrior,
    initial_t_target_sensor_end: &Pose,
    params: &NdtParams,
) -> Result<CtRegistration, RegistrationError> {
    let priors = CtPriors {
        start: *prior,
        rate: None,
        displacement: None,
    };
    register_ct_ndt_with_priors(
        map,
        source,
        scan,
        &priors,
        initial_t_target_sensor_end,
        params,
    )
}

/// The priors of [`register_ct_ndt_with_priors`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CtPriors {
    /// The prior on the start pose `T^s`.
    pub start: StartPrior,
    /// An optional prior on the turn over the scan (see [`RatePrior`]).
    pub rate: Option<RatePrior>,
    /// An optional prior on the displacement of the target origin over the
    /// scan (see [`DisplacementPrior`]).
    pub displacement: Option<DisplacementPrior>,
}

impl CtPriors {
    /// Rejects an invalid start, rate or displacement prior.
    pub fn validate(&self) -> Result<(), RegistrationError> {
        self.start.validate()?;
        if let Some(rate) = &self.rate {
            rate.validate()?;
        }
        if let Some(d) = &self.displacement {
            d.validate()?;
        }
        Ok(())
    }

    /// True with a rate or displacement prior (a prior on the motion over
    /// the scan, which ties the start pose to the end pose).
    fn has_motion_prior(&self) -> bool {
        self.rate.is_some() || self.displacement.is_some()
    }

    /// Adds every prior to `joint` at `(start, end)`.
    fn add_to(&self, joint: &mut Joint, start: &Pose, end: &Pose) {
        joint.add_prior(start, &self.start);
        if let Some(rate) = &self.rate {
            joint.add_rate_prior(start, end, rate);
        }
        if let Some(d) = &self.displacement {
            joint.add_displacement_prior(start, end, d);
        }
    }
}

/// [`register_ct_ndt_free_start`] with, optionally, a [`RatePrior`] on the
/// turn and a [`DisplacementPrior`] on the displacement over the scan as
/// well (with both, the start prior may be zero: the points then fix the
/// pose, the priors its motion over the scan). The reported information of `T^e` includes
/// both priors (start marginalised out). With a motion prior the first
/// increments use every `coarse_stride`-th point, as NDT's coarse phase,
/// until both increments fall below `coarse_switch` times their
/// thresholds; convergence is tested on every point. Same errors, plus an invalid
/// rate prior.
pub fn register_ct_ndt_with_priors(
    map: &NdtMap,
    source: &[Point],
    scan: &ScanTimes,
    priors: &CtPriors,
    initial_t_target_sensor_end: &Pose,
    params: &NdtParams,
) -> Result<CtRegistration, RegistrationError> {
    params.validate()?;
    scan.validate()?;
    priors.validate()?;
    check_pose("initial_t_target_sensor_end", initial_t_target_sensor_end)?;
    let (points, skipped) = timed_points(source, scan)?;
    let constrained = constrained_directions(map, source, initial_t_target_sensor_end, params);
    let solver = JointSolver {
        map,
        points: &points,
        priors,
        basis: constrained.as_ref().and_then(stacked_basis),
        params,
    };
    let solved = solver.run(*initial_t_target_sensor_end)?;
    let joint = match solved.final_joint {
        Some(j) => j,
        None => solver.evaluate(&solved.start, &solved.end),
    };
    if joint.inliers == 0 {
        return Err(no_match(solved.iterations, params));
    }
    let n = joint.inliers as f64;
    let end_registration = Registration {
        t_target_sensor: solved.end,
        converged: solved.converged,
        iterations: solved.iterations,
        cost: Cost {
            total: joint.cost,
            mean: joint.cost / n,
        },
        inliers: joint.inliers,
        valid_points: points.len(),
        skipped_non_finite: skipped,
        mean_squared_distance_m2: joint.squared_distance / n,
        f_conv_m2: None,
        information: joint.end_information(),
        last_increment: solved.last_end_increment,
        degenerate_directions: constrained.as_ref().map_or(0, Constrained::dropped),
        weakest_lever_arm_m: constrained
            .as_ref()
            .map_or(f64::NAN, |c| c.weakest_lever_arm_m),
        held_translations: constrained
            .as_ref()
            .map_or(0, Constrained::held_translations),
        weakest_translation_cosine: constrained
            .as_ref()
            .map_or(f64::NAN, |c| c.weakest_translation_cosine),
        geometric_information: constrained.map(|c| c.information),
    };
    Ok(CtRegistration {
        end: end_registration,
        t_target_sensor_start: solved.start,
        start_correction: increment_of(&solved.start.ominus(&priors.start.t_target_sensor)),
    })
}

/// The finite points of `source` with their interpolation factors `u`
/// (Eq. 13), and how many were skipped as non-finite.
fn timed_points(
    source: &[Point],
    scan: &ScanTimes,
) -> Result<(Vec<TimedPoint>, usize), RegistrationError> {
    if source.is_empty() {
        return Err(RegistrationError::EmptyCloud);
    }
    let points: Vec<TimedPoint> = source
        .iter()
        .filter(|p| position_is_finite(p) && p.t.is_finite())
        .map(|p| (p.position(), scan.factor(p.t)))
        .collect();
    if points.is_empty() {
        return Err(RegistrationError::AllPointsNonFinite {
            count: source.len(),
        });
    }
    let skipped = source.len() - points.len();
    Ok((points, skipped))
}

fn no_match(iteration: usize, params: &NdtParams) -> RegistrationError {
    RegistrationError::NoCorrespondences {
        iteration,
        max_distance_m: params.max_distance_m,
    }
}

/// Where [`JointSolver::run`] stopped.
struct Solved {
    start: Pose,
    end: Pose,
    iterations: usize,
    converged: bool,
    last_end_increment: Increment,
    /// The last full linearisation when converged (at the pose before the
    /// last increment, as [`crate::register_ndt`] reports).
    final_joint: Option<Joint>,
}

/// Gauss-Newton on the stacked `[δ^s; δ^e]` of one scan.
struct JointSolver<'a> {
    map: &'a NdtMap,
    points: &'a [TimedPoint],
    priors: &'a CtPriors,
    /// `blockdiag(Q, Q)` of the well-constrained directions, if any held.
    basis: Option<DMatrix<f64>>,
    params: &'a NdtParams,
}

impl JointSolver<'_> {
    /// The data term over every point, the priors added to `h` and `g`;
    /// `cost` and `squared_distance` are the points' alone.
    fn evaluate(&self, start: &Pose, end: &Pose) -> Joint {
        let mut joint = linearise(self.map, self.points, start, end, self.params);
        let data_only = (joint.cost, joint.squared_distance);
        self.priors.add_to(&mut joint, start, end);
        (joint.cost, joint.squared_distance) = data_only;
        joint
    }

    /// Iterates from `(prior mean, initial_end)` until Table 1's test holds
    /// on the end pose, with the start pose's increment within
    /// `START_TOLERANCE` times it, or `max_iterations` is reached.
    /// Both at 1× waited for twelve increments to fall below the
    /// thresholds together, while association changes keep them chattering
    /// at about 1 mm.
    fn run(&self, initial_end: Pose) -> Result<Solved, RegistrationError> {
        let params = self.params;
        let rot_tol = params.termination_rotation_deg.to_radians();
        let below = |inc: &Increment, factor: f64| {
            inc.rotation_rad < rot_tol * factor
                && inc.translation_m < params.termination_translation_m * factor
        };
        let mut solved = Solved {
            start: self.priors.start.t_target_sensor,
            end: initial_end,
            iterations: 0,
            converged: false,
            last_end_increment: Increment::default(),
            final_joint: None,
        };
        let mut coarse = CoarsePhase::new(self.points, self.priors, params);
        for it in 0..params.max_iterations {
            let mut joint = coarse.linearise(self, &solved.start, &solved.end);
            if joint.inliers == 0 {
                return Err(no_match(it, params));
            }
            let data_only = (joint.cost, joint.squared_distance);
            self.priors.add_to(&mut joint, &solved.start, &solved.end);
            let eps =
                joint
                    .solve(self.basis.as_ref())
                    .ok_or(RegistrationError::DegenerateSystem {
                        iteration: it,
                        inliers: joint.inliers,
                    })?;
            (joint.cost, joint.squared_distance) = data_only;
            let (eps_s, eps_e) = split(&eps);
            solved.start = solved.start.oplus(&eps_s);
            solved.end = solved.end.oplus(&eps_e);
            solved.iterations = it + 1;
            let (inc_s, inc_e) = (increment_of(&eps_s), increment_of(&eps_e));
            solved.last_end_increment = inc_e;
            if coarse.active() {
                let switch = params.coarse_switch;
                if below(&inc_e, switch) && below(&inc_s, switch * START_TOLERANCE) {
                    coarse.end();
                }
            } else if below(&inc_e, 1.0) && below(&inc_s, START_TOLERANCE) {
                solved.converged = true;
                solved.final_joint = Some(joint);
                break;
            }
        }
        Ok(solved)
    }
}

/// NDT's coarse phase for the joint problem: every `coarse_stride`-th
/// point, the data term scaled by the stride so that it weighs against the
/// priors as the full cloud does.
///
/// Under the start prior alone there is no coarse phase: a strided
/// subsample left the start pose 2 cm from the full-resolution optimum
/// along its weak directions (benchmark frame), and the fine phase spent
/// five iterations bringing it back. With a motion prior the start pose is
/// tied to the end pose, and the coarse phase runs as in NDT.
struct CoarsePhase {
    stride: usize,
    subset: Vec<TimedPoint>,
}

impl CoarsePhase {
    fn new(points: &[TimedPoint], priors: &CtPriors, params: &NdtParams) -> Self {
        let stride = if priors.has_motion_prior() {
            params.coarse_stride.max(1)
        } else {
            1
        };
        let subset = if stride > 1 {
            points.iter().step_by(stride).copied().collect()
        } else {
            Vec::new()
        };
        Self { stride, subset }
    }

    fn active(&self) -> bool {
        self.stride > 1
    }

    fn end(&mut self) {
        (self.stride, self.subset) = (1, Vec::new());
    }

    /// The data term at `(start, end)`: on the subset, scaled, while the
    /// phase is active and the subset has at least 12 inliers; otherwise
    /// (ending the phase) on every point.
    fn linearise(&mut self, solver: &JointSolver, start: &Pose, end: &Pose) -> Joint {
        let (map, params) = (solver.map, solver.params);
        if self.active() {
            let mut joint = linearise(map, &self.subset, start, end, params);
            if joint.inliers >= 12 {
                joint.h *= self.stride as f64;
                joint.g *= self.stride as f64;
                return joint;
            }
            // Too sparse a subset: continue on every point.
            self.end();
        }
        linearise(map, solver.points, start, end, params)
    }
}

/// `blockdiag(Q, Q)` for a restricted basis `Q` (the same rotations are
/// held at both ends); `None` when nothing is held.
fn stacked_basis(c: &Constrained) -> Option<DMatrix<f64>> {
    let k = c.basis.len();
    if k == 6 {
        return None;
    }
    let mut q = DMatrix::zeros(12, 2 * k);
    for (j, b) in c.basis.iter().enumerate() {
        for i in 0..6 {
            q[(i, j)] = b[i];
            q[(i + 6, j + k)] = b[i];
        }
    }
    Some(q)
}

#[cfg(test)]
#[path = "free_start_tests.rs"]
mod tests;
