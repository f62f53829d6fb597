//! The stages of one [`TemplateMatcher::acquire`] call, in order: the
//! frame's finite points and centre, template matching (seed 002 §2),
//! ICP refinement of the candidates with the second chance, and the
//! outcome with the f_CONV check (§4.5).

use super::density::stride_for;
use super::refinements::Refinements;
use super::scoring::{Ranked, Sensed};
use super::{TemplateMatcher, ms_since};
use crate::correlation::{Centering, Correlator, d_bor};
use crate::error::AcquisitionError;
use crate::outcome::AcquisitionOutcome;
use crate::refine::{Refined, refine_with_stages};
use crate::visibility::SensedTree;
use nalgebra::Vector3;
use spacepose_geometry::Point;
use std::time::Instant;

/// One frame's finite points and the centre they are matched at.
pub(super) struct Frame {
    /// The finite points of the cloud.
    pub(super) finite: Vec<Point>,
    /// Their positions (sensor frame).
    pub(super) positions: Vec<Vector3<f64>>,
    /// How the centre is taken, for the sensed cloud and the templates.
    centering: Centering,
    /// The position estimate of seed 002 §2.1: the (trimmed) centroid.
    centre: Vector3<f64>,
    /// Index of the density level the frame was thinned to.
    pub(super) density: usize,
}

/// The template-matching result of one frame.
pub(super) struct Matched {
    /// The scored templates, best C first (see `match_templates`).
    pub(super) ranked: Vec<Ranked>,
    /// Templates rendered.
    generated: usize,
    /// Templates rejected by Eq. (3).
    rejected: usize,
    /// Correlations computed at full resolution.
    evaluated: usize,
    /// C of the best template.
    best_c: f64,
}

/// Wall times of one acquisition.
#[derive(Clone, Copy)]
pub(super) struct Timing {
    /// When the acquisition started.
    pub(super) start: Instant,
    /// Template matching (ms).
    pub(super) matching_ms: f64,
    /// ICP refinement (ms).
    pub(super) refinement_ms: f64,
}

impl Matched {
    /// C of grid template `k` (the best C if `k` was not ranked).
    fn correlation_of(&self, k: usize) -> f64 {
        self.ranked
            .iter()
            .find(|r| r.0 == k)
            .map_or(self.best_c, |r| r.1)
    }
}

impl TemplateMatcher {
    /// Acquires the pose of the target in `cloud` (one frame, sensor
    /// frame): template matching, ICP refinement of the best candidates,
    /// f_CONV check. Non-finite points are ignored.
    ///
    /// Errors: [`AcquisitionError::TooFewPoints`] for a cloud with fewer
    /// than `min_points` finite points (sparse or all-NaN: never a pose);
    /// [`AcquisitionError::NoTemplate`] when no template could be
    /// correlated. A failed refinement is not an error: the outcome is then
    /// not accepted.
    pub fn acquire(&self, cloud: &[Point]) -> Result<AcquisitionOutcome, AcquisitionError> {
        let start = Instant::now();
        let frame = self.prepare(cloud)?;
        let matched = self.match_frame(&frame)?;
        let matching_ms = ms_since(start);

        // Template solution(s): grid attitude, origin from the centroid alignment.
        let refine_start = Instant::now();
        let sensed_tree = SensedTree::new(&frame.positions);
        let mut refinements = self.refine_candidates(&matched.ranked, &frame, &sensed_tree);
        self.add_second_chance(&mut refinements, &frame, &sensed_tree);
        let density = &self.levels[frame.density];
        self.add_twins(density, &mut refinements, &frame, &sensed_tree);
        let timing = Timing {
            start,
            matching_ms,
            refinement_ms: ms_since(refine_start),
        };
        Ok(self.outcome(&frame, &matched, &refinements, timing))
    }

    /// The finite points of `cloud`, thinned to the point budget (see
    /// [`super::density`]), their positions and centre.
    /// [`AcquisitionError::TooFewPoints`] with fewer than `min_points`
    /// finite points, or when the centre cannot be taken (`valid: 0`).
    pub(super) fn prepare(&self, cloud: &[Point]) -> Result<Frame, AcquisitionError> {
        let mut finite: Vec<Point> = cloud.iter().copied().filter(Point::is_finite).collect();
        if finite.len() < self.config.min_points {
            return Err(AcquisitionError::TooFewPoints {
                valid: finite.len(),
                total: cloud.len(),
                required: self.config.min_points,
            });
        }
        let budget = self.config.max_sensed_points;
        let stride = stride_for(finite.len(), budget, self.levels.len());
        if stride > 1 {
            finite = finite.into_iter().step_by(stride * stride).collect();
        }
        let positions: Vec<Vector3<f64>> = finite.iter().map(Point::position).collect();
        let centering = self.centering();
        let mut scratch = Vec::new();
        let centre =
            centering
                .centre(&positions, &mut scratch)
                .ok_or(AcquisitionError::TooFewPoints {
                    valid: 0,
                    total: cloud.len(),
                    required: self.config.min_points,
                })?;
        Ok(Frame {
            finite,
            positions,
            centering,
            centre,
            density: stride - 1,
        })
    }

    /// The centring of clouds and templates: the centroid trimmed by
    /// `trim` when `trimmed_centroid` is set, else the mean.
    fn centering(&self) -> Centering {
        if self.config.trimmed_centroid {
            Centering::Trimmed(self.config.trim)
        } else {
            Centering::Mean
        }
    }

    /// Template matching of `frame` (seed 002 §2): the templates scored by
    /// C of Eq. (1) against the sensed points (see `match_templates`).
    /// [`AcquisitionError::NoTemplate`] when no template was correlated.
    pub(super) fn match_frame(&self, frame: &Frame) -> Result<Matched, AcquisitionError> {
        let correlator = Correlator::new(
            &frame.positions,
            &frame.centre,
            frame.centering,
            self.config.max_correlation_points,
            self.config.symmetric_correlation,
        );
        let sensed = Sensed {
            density: &self.levels[frame.density],
            correlator: &correlator,
            centre: frame.centre,
            d_bor: d_bor(&frame.positions),
        };
        let (ranked, generated, rejected) = self.match_templates(&sensed);
        // Correlations computed at full resolution (the fine pass only,
        // with coarse-to-fine).
        let evaluated = match self.config.coarse_to_fine {
            Some(c) if self.levels[frame.density].coarse.is_some() => ranked.len().min(c.keep),
            _ => ranked.len(),
        };
        let Some(&(_, best_c, _)) = ranked.first() else {
            return Err(AcquisitionError::NoTemplate {
                generated,
                rejected,
            });
        };
        Ok(Matched {
            ranked,
            generated,
            rejected,
            evaluated,
            best_c,
        })
    }

    /// The candidates of `ranked` (see `screened_candidates`) refined by
    /// ICP on every finite point of `frame`, each with its unexplained
    /// fraction against `sensed_tree` (1 for a failed refinement).
    pub(super) fn refine_candidates(
        &self,
        ranked: &[Ranked],
        frame: &Frame,
        sensed_tree: &SensedTree,
    ) -> Refinements {
        let density = &self.levels[frame.density];
        let (candidates, starts, screened) = self.screened_candidates(
            density,
            ranked,
            &frame.finite,
            (&frame.positions, &frame.centre),
            frame.centering,
            sensed_tree,
        );
        // After screening, the wide stages have been run: only the
        // narrowest is repeated, on the full model, before the final one.
        let stages = &self.config.icp_stages_m;
        let stages = match screened {
            0 => &stages[..],
            _ => &stages[stages.len().saturating_sub(1)..],
        };
        let refined: Vec<Result<Refined, String>> = starts
            .iter()
            .map(|pose| {
                refine_with_stages(
                    &self.icp_model,
                    self.stage_model(),
                    &frame.finite,
                    pose,
                    &self.config,
                    stages,
                )
                .map_err(|e| e.to_string())
            })
            .collect();
        let unexplained: Vec<f64> = refined
            .iter()
            .map(|r| match r {
                Ok(r) => self.unexplained(density, sensed_tree, &r.t_sensor_target),
                Err(_) => 1.0,
            })
            .collect();
        Refinements {
            candidates,
            refined,
            unexplained,
            screened,
            ambiguous: false,
        }
    }

    /// The second chance (see [`crate::TemplateMatchingConfig::revote`]):
    /// when `revote` is on and the best refinement (see
    /// [`Refinements::best`]) fails the acceptance test, each attempt
    /// of `second_chance` is appended as a refinement of that candidate.
    pub(super) fn add_second_chance(
        &self,
        refinements: &mut Refinements,
        frame: &Frame,
        sensed_tree: &SensedTree,
    ) {
        let w = self.config.unexplained_weight_m2;
        if let Some((i, r)) = refinements.best(w)
            && let u = refinements.unexplained[i]
            && self.config.revote
            // The uncapped f_CONV decides whether to try again: a flip can
            // fit most points and still leave a few far off.
            && !self.acceptable(r.msd_all_m2, u)
        {
            for (again, u_again) in self.second_chance(
                &self.levels[frame.density],
                &r.t_sensor_target,
                &frame.finite,
                &frame.positions,
                sensed_tree,
            ) {
                refinements.push(i, Ok(again), u_again);
            }
        }
    }

    /// The outcome of one acquisition: the chosen solution (see
    /// [`Refinements::choose`]), its template and the f_CONV check
    /// (seed 002 §4.5), with the counts and wall times of the stages.
    pub(super) fn outcome(
        &self,
        frame: &Frame,
        matched: &Matched,
        refinements: &Refinements,
        timing: Timing,
    ) -> AcquisitionOutcome {
        let chosen = refinements.choose(self.config.unexplained_weight_m2);
        let (chosen_k, coarse) = refinements.candidates[chosen.rank];
        let centre = frame.centre;
        AcquisitionOutcome {
            t_sensor_target: chosen.pose,
            t_sensor_target_coarse: coarse,
            euler_coarse: self.grid[chosen_k].0,
            centroid_m: [centre.x, centre.y, centre.z],
            correlation_m2: matched.correlation_of(chosen_k),
            f_conv_m2: chosen.f_conv_m2,
            unexplained_fraction: chosen.unexplained_fraction,
            accepted: self.acceptable(chosen.f_conv_m2, chosen.unexplained_fraction)
                && !refinements.ambiguous,
            templates_generated: matched.generated,
            templates_evaluated: matched.evaluated,
            templates_rejected: matched.rejected,
            points_used: frame.finite.len(),
            time_ms: ms_since(timing.start),
            matching_ms: timing.matching_ms,
            refinement_ms: timing.refinement_ms,
            candidates_refined: refinements.candidates.len(),
            candidates_screened: refinements.screened,
            chosen_rank: chosen.rank,
            icp_iterations: chosen.iterations,
            icp_converged: chosen.converged,
            icp_inlier_fraction: chosen.inlier_fraction,
            refinement_error: chosen.refinement_error,
            twin_ambiguous: refinements.ambiguous,
        }
    }
}
