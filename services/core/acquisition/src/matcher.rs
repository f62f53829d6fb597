//! The on-line template matcher of seed 002 §2 (Fig. 2) with ICP
//! refinement and the f_CONV failure check of §4.5 (Fig. 10).

use crate::config::{TemplateMatchingConfig, Threads};
use crate::correlation::{Centering, Correlator, d_bor, d_bor_passes};
use crate::error::AcquisitionError;
use crate::grid::euler_grid;
use crate::outcome::AcquisitionOutcome;
use crate::refine::{Refined, refine_with_stages, screen};
use crate::slide_search::{SLIDE_STEP_M, principal_axis, slide_poses};
use crate::template::TemplateRenderer;
use crate::translation_vote::{VoteScratch, vote_translation};
use crate::visibility::SensedTree;
use nalgebra::{Rotation3, Vector3};
use rayon::prelude::*;
use spacepose_geometry::{Euler321, Point, Pose, so3};
use spacepose_lidar_sim::{LidarSimulator, SensorConfig};
use spacepose_model::Target;
use spacepose_registration::IcpModel;
use stages::Timing;
use std::f64::consts::PI;
use std::sync::Arc;
use std::time::Instant;

#[path = "matcher_stages.rs"]
mod stages;

/// Seed of the model-cloud sampling (any fixed value: the cloud is deterministic).
const MODEL_SEED: u64 = 0x5eed_0002;

/// Points of the sensed cloud and of the template in a translation vote
/// (150 × 150 votes).
const VOTE_POINTS: usize = 150;

/// How one template fared.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Score {
    /// Fewer than 3 points (the target out of the field of view).
    Empty,
    /// Rejected by Eq. (3).
    Rejected,
    /// C of Eq. (1) and the target origin it implies (sensor frame): the
    /// render position moved by the centroid alignment.
    Scored(f64, Vector3<f64>),
}

/// A scored template: grid index, C, implied target origin.
type Ranked = (usize, f64, Vector3<f64>);

/// Per-acquisition inputs shared by every template evaluation.
struct Sensed<'a> {
    correlator: &'a Correlator,
    centre: Vector3<f64>,
    d_bor: f64,
}

/// The template matcher for one target and one sensor: attitude grid,
/// template renderers and ICP model are built once here.
#[derive(Debug)]
pub struct TemplateMatcher {
    target: Arc<Target>,
    sensor: SensorConfig,
    config: TemplateMatchingConfig,
    grid: Vec<(Euler321, Rotation3<f64>)>,
    renderer: TemplateRenderer,
    coarse_renderer: Option<TemplateRenderer>,
    /// Tolerance of the reverse check (rad): `unexplained_spacings` times
    /// the sensor's ray spacing.
    tolerance_rad: f64,
    icp_model: IcpModel,
    /// The coarser model of the wide ICP stages, if configured.
    stage_model: Option<IcpModel>,
    /// Reach of the translation vote (m): the radius of the model's
    /// bounding box.
    vote_reach_m: f64,
}

impl TemplateMatcher {
    /// Validates the configuration and the sensor, builds the Euler grid,
    /// the template renderers and the ICP model (a surface sample of the
    /// mesh at `model_spacing_m` with its lookup grid, ~1 s).
    pub fn new(
        target: Arc<Target>,
        sensor: SensorConfig,
        config: TemplateMatchingConfig,
    ) -> Result<Self, AcquisitionError> {
        config.validate()?;
        // The simulator's own validation of the sensor and the materials.
        LidarSimulator::new(target.clone(), sensor.clone())?;
        let grid = euler_grid(config.delta_deg)?
            .into_iter()
            .map(|e| (e, e.to_rotation()))
            .collect();
        let renderer = TemplateRenderer::new(target.clone(), &sensor, config.template_stride);
        let coarse_renderer = config
            .coarse_to_fine
            .map(|c| TemplateRenderer::new(target.clone(), &sensor, c.stride));
        let tolerance_rad = config.unexplained_spacings
            * TemplateRenderer::new(target.clone(), &sensor, 1).ray_spacing_rad();
        let model = target.sample_surface(config.model_spacing_m, MODEL_SEED);
        let vote_reach_m = bounding_radius(&model);
        let with_far = |m: IcpModel| {
            let mut levels = config.far_lookup.iter().flat_map(|f| &f.levels);
            levels.try_fold(m, |m, l| m.with_far_lookup(l.margin_m, l.resolution_m))
        };
        // Both models get the far lookup: the refinement's widest stage
        // after screening runs on the full model.
        let (icp_model, stage_model) = if config.stage_model_spacing_m > 0.0 {
            let coarse = target.sample_surface(config.stage_model_spacing_m, MODEL_SEED);
            (
                with_far(IcpModel::new(&model)?)?,
                Some(with_far(IcpModel::new(&coarse)?)?),
            )
        } else {
            // The full model serves the wide stages too.
            (with_far(IcpModel::new(&model)?)?, None)
        };
        Ok(Self {
            target,
            sensor,
            config,
            grid,
            renderer,
            coarse_renderer,
            tolerance_rad,
            icp_model,
            stage_model,
            vote_reach_m,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &TemplateMatchingConfig {
        &self.config
    }

    /// The sensor the templates are rendered for.
    pub fn sensor(&self) -> &SensorConfig {
        &self.sensor
    }

    /// The target.
    pub fn target(&self) -> &Arc<Target> {
        &self.target
    }

    /// The ICP model (target surface sample with its lookup structures).
    pub fn icp_model(&self) -> &IcpModel {
        &self.icp_model
    }

    /// The model of the wide ICP stages (the ICP model when
    /// `stage_model_spacing_m` is 0).
    pub fn stage_model(&self) -> &IcpModel {
        self.stage_model.as_ref().unwrap_or(&self.icp_model)
    }

    /// The grid attitudes `(Euler angles, rotation)`.
    pub fn grid(&self) -> &[(Euler321, Rotation3<f64>)] {
        &self.grid
    }

    /// Number of grid attitudes (templates per full pass).
    pub fn grid_len(&self) -> usize {
        self.grid.len()
    }

    /// Rays per full-resolution template.
    pub fn template_rays(&self) -> usize {
        self.renderer.rays()
    }

    /// Sets f_MAX (m²), e.g. after `spacepose calibrate fconv`.
    pub fn set_f_max_m2(&mut self, f_max_m2: f64) -> Result<(), AcquisitionError> {
        let config = TemplateMatchingConfig {
            f_max_m2,
            ..self.config.clone()
        };
        config.validate()?;
        self.config = config;
        Ok(())
    }

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
        let timing = Timing {
            start,
            matching_ms,
            refinement_ms: ms_since(refine_start),
        };
        Ok(self.outcome(&frame, &matched, &refinements, timing))
    }

    /// The candidates to refine, `(grid index, template pose)`, the poses
    /// their refinement starts from, and how many were screened: the
    /// `icp_candidates` best distinct templates, or with screening the
    /// `icp_candidates` best after the short ICP (re-ranked by the reverse
    /// check, see `screen_rerank`), from where it left them.
    fn screened_candidates(
        &self,
        ranked: &[(usize, f64, Vector3<f64>)],
        cloud: &[Point],
        (positions, centre): (&[Vector3<f64>], &Vector3<f64>),
        centering: Centering,
        sensed: &SensedTree,
    ) -> (Vec<(usize, Pose)>, Vec<Pose>, usize) {
        let c = &self.config;
        let keep = c.icp_candidates;
        let subsample = strided(cloud, c.screen_max_points);
        let mut count = keep.max(c.screen_candidates);
        if c.screen_point_budget > 0 {
            count = count.min((c.screen_point_budget / subsample.len().max(1)).max(keep));
        }
        let templates: Vec<(usize, Pose)> = self
            .distinct_candidates(ranked, count)
            .into_iter()
            .map(|(k, origin)| {
                let r = self.grid[k].1;
                let origin = self.recentre(&r, origin, centre, centering);
                (k, Pose::new(r, self.vote(&r, origin, positions)))
            })
            .collect();
        let unscreened = |t: Vec<(usize, Pose)>| {
            let t: Vec<(usize, Pose)> = t.into_iter().take(keep).collect();
            let starts = t.iter().map(|c| c.1).collect();
            (t, starts, 0)
        };
        if templates.len() <= keep {
            return unscreened(templates);
        }
        let mut screened: Vec<(f64, usize, Pose)> = templates
            .iter()
            .enumerate()
            .filter_map(|(i, (_, pose))| {
                screen(self.stage_model(), &subsample, pose, c)
                    .ok()
                    .map(|(p, score)| (score, i, p))
            })
            .collect();
        if screened.is_empty() {
            // Every short ICP failed: refine the best templates unscreened.
            return unscreened(templates);
        }
        screened.sort_by(|a, b| a.0.total_cmp(&b.0));
        if c.screen_rerank > keep && c.unexplained_weight_m2 > 0.0 {
            screened.truncate(c.screen_rerank);
            for s in &mut screened {
                s.0 += c.unexplained_weight_m2 * self.unexplained(sensed, &s.2);
            }
            screened.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        screened.truncate(keep);
        let chosen = screened.iter().map(|&(_, i, _)| templates[i]).collect();
        let starts = screened.iter().map(|&(_, _, p)| p).collect();
        (chosen, starts, templates.len())
    }

    /// The acceptance test: f_CONV ≤ f_MAX (seed 002 §4.5) and the
    /// unexplained fraction ≤ `u_max`.
    fn acceptable(&self, f_conv_m2: f64, unexplained: f64) -> bool {
        f_conv_m2.is_finite()
            && f_conv_m2 <= self.config.f_max_m2
            && unexplained <= self.config.u_max
    }

    /// The second chance of a rejected pose (see
    /// [`TemplateMatchingConfig::revote`] and `revote_flips`): each
    /// attitude tried, with its result and unexplained fraction.
    fn second_chance(
        &self,
        rejected: &Pose,
        cloud: &[Point],
        positions: &[Vector3<f64>],
        sensed: &SensedTree,
    ) -> Vec<(Refined, f64)> {
        let flips = if self.config.revote_flips { 3 } else { 0 };
        let half_turn = |a: usize| Rotation3::from_axis_angle(&Vector3::ith_axis(a), PI);
        std::iter::once(rejected.rotation)
            .chain((0..flips).map(|a| rejected.rotation * half_turn(a)))
            .filter_map(|r| {
                let pose = Pose::new(r, rejected.translation);
                self.revote(&pose, cloud, positions, sensed)
            })
            .chain(self.slide(rejected, cloud, positions, sensed))
            .collect()
    }

    /// The slide search of the second chance (see
    /// [`TemplateMatchingConfig::slide_reach_m`]): the rejected pose moved
    /// along the sensed cloud's principal axis by every
    /// [`SLIDE_STEP_M`] within the reach, each screened by a short ICP
    /// (see [`screen`]); the best, if it scores better than the unmoved
    /// pose, is refined from the final stage on. `None` when the search is
    /// off, finds nothing better, or the refinement fails.
    fn slide(
        &self,
        rejected: &Pose,
        cloud: &[Point],
        positions: &[Vector3<f64>],
        sensed: &SensedTree,
    ) -> Option<(Refined, f64)> {
        let reach = self.config.slide_reach_m;
        if reach <= 0.0 {
            return None;
        }
        let subsample = strided(cloud, self.config.screen_max_points);
        let axis = principal_axis(positions)?;
        let screened =
            |pose: &Pose| screen(self.stage_model(), &subsample, pose, &self.config).ok();
        let (_, unmoved) = screened(rejected)?;
        let (start, score) = slide_poses(rejected, &axis, reach, SLIDE_STEP_M)
            .iter()
            .filter_map(screened)
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        if score >= unmoved {
            return None;
        }
        let stages = &self.config.icp_stages_m;
        let again = refine_with_stages(
            &self.icp_model,
            self.stage_model(),
            cloud,
            &start,
            &self.config,
            &stages[stages.len().saturating_sub(1)..],
        )
        .ok()?;
        let u = self.unexplained(sensed, &again.t_sensor_target);
        Some((again, u))
    }

    /// One attempt of the second chance: the attitude of `rejected`, placed
    /// by a translation vote from its refined position, refined again
    /// through every stage. `None` when the vote is off or the refinement
    /// fails; else the result and its unexplained fraction.
    fn revote(
        &self,
        rejected: &Pose,
        cloud: &[Point],
        positions: &[Vector3<f64>],
        sensed: &SensedTree,
    ) -> Option<(Refined, f64)> {
        if self.config.translation_vote_bin_m <= 0.0 {
            return None;
        }
        let r = rejected.rotation;
        let origin = self.vote(&r, rejected.translation, positions);
        let again = refine_with_stages(
            &self.icp_model,
            self.stage_model(),
            cloud,
            &Pose::new(r, origin),
            &self.config,
            &self.config.icp_stages_m,
        )
        .ok()?;
        let u = self.unexplained(sensed, &again.t_sensor_target);
        Some((again, u))
    }

    /// The unexplained fraction of `t_sensor_target` (see
    /// [`crate::visibility`]).
    fn unexplained(&self, sensed: &SensedTree, t_sensor_target: &Pose) -> f64 {
        let mut template = Vec::new();
        self.renderer.render_into(
            &t_sensor_target.rotation,
            &t_sensor_target.translation,
            &mut template,
        );
        sensed.unexplained_fraction(&template, self.tolerance_rad)
    }

    /// The target origin of attitude `r` re-centred `recentre_iterations`
    /// times: the template is rendered with the origin at `origin`, and the
    /// origin moves by the sensor centre minus that template's centre.
    /// Templates are scored rendered at the sensor centroid, and when the
    /// field of view clips the target that render shows another part than
    /// the sensor saw, so its alignment leaves the origin metres off; each
    /// re-render clips like the sensor did.
    fn recentre(
        &self,
        r: &Rotation3<f64>,
        mut origin: Vector3<f64>,
        centre: &Vector3<f64>,
        centering: Centering,
    ) -> Vector3<f64> {
        let (mut template, mut scratch) = (Vec::new(), Vec::new());
        for _ in 0..self.config.recentre_iterations {
            self.renderer.render_into(r, &origin, &mut template);
            if template.len() < 3 {
                break;
            }
            match centering.centre(&template, &mut scratch) {
                Some(c) => origin += centre - c,
                None => break,
            }
        }
        origin
    }

    /// The origin of attitude `r` moved by the translation vote of its
    /// template rendered at `origin` against the sensed `positions` (see
    /// [`crate::translation_vote`]; unchanged when the vote is off or
    /// finds nothing).
    fn vote(
        &self,
        r: &Rotation3<f64>,
        origin: Vector3<f64>,
        positions: &[Vector3<f64>],
    ) -> Vector3<f64> {
        let bin = self.config.translation_vote_bin_m;
        if bin <= 0.0 {
            return origin;
        }
        let template = self.renderer.render(r, &origin);
        let mut scratch = VoteScratch::default();
        let reach = self.vote_reach_m;
        vote_translation(
            positions,
            &template,
            (bin, reach),
            VOTE_POINTS,
            &mut scratch,
        )
        .map_or(origin, |t| origin + t)
    }

    /// The `count` best templates, skipping any closer than
    /// `candidate_separation_deg` to a better one: `(grid index, origin)`.
    fn distinct_candidates(
        &self,
        ranked: &[(usize, f64, Vector3<f64>)],
        count: usize,
    ) -> Vec<(usize, Vector3<f64>)> {
        let min_sep = self.config.candidate_separation_deg.to_radians();
        let mut chosen: Vec<(usize, Vector3<f64>)> = Vec::new();
        for &(k, _, centre) in ranked {
            if chosen.len() == count {
                break;
            }
            let r = &self.grid[k].1;
            if chosen
                .iter()
                .all(|(j, _)| so3::distance(&self.grid[*j].1, r) >= min_sep)
            {
                chosen.push((k, centre));
            }
        }
        chosen
    }

    /// Renders and scores the templates: `(grid index, C, implied origin)`
    /// sorted by C, templates generated, templates rejected by Eq. (3).
    fn match_templates(&self, sensed: &Sensed) -> (Vec<Ranked>, usize, usize) {
        let all: Vec<(usize, Vector3<f64>)> =
            (0..self.grid.len()).map(|k| (k, sensed.centre)).collect();
        let (first, fine) = match (&self.coarse_renderer, self.config.coarse_to_fine) {
            (Some(coarse), Some(c)) => (coarse, Some(c.keep)),
            _ => (&self.renderer, None),
        };
        let scores = self.score(&all, first, sensed, self.config.fast);
        let mut generated = scores.len();
        let rejected = scores.iter().filter(|s| s.1 == Score::Rejected).count();
        let mut ranked = rank(&scores);
        if let Some(keep) = fine {
            // Rendered at the sensor centroid as in the coarse pass (rendering
            // where the alignment put the origin measured worse); Eq. (3) was
            // applied on the coarse pass.
            let kept: Vec<(usize, Vector3<f64>)> = ranked
                .iter()
                .take(keep)
                .map(|r| (r.0, sensed.centre))
                .collect();
            let scores = self.score(&kept, &self.renderer, sensed, false);
            generated += scores.len();
            let coarse_rest = ranked.split_off(keep.min(ranked.len()));
            ranked = rank(&scores);
            // Candidate screening may reach beyond the fine pass: the other
            // templates follow in their coarse order.
            ranked.extend(coarse_rest);
        }
        (ranked, generated, rejected)
    }

    /// Scores the grid attitudes `jobs` (grid index, render position) with
    /// `renderer`.
    fn score(
        &self,
        jobs: &[(usize, Vector3<f64>)],
        renderer: &TemplateRenderer,
        sensed: &Sensed,
        fast: bool,
    ) -> Vec<(usize, Score)> {
        let one = |&(k, at): &(usize, Vector3<f64>),
                   template: &mut Vec<Vector3<f64>>,
                   scratch: &mut Vec<f64>| {
            renderer.render_into(&self.grid[k].1, &at, template);
            if template.len() < 3 {
                return (k, Score::Empty);
            }
            if fast && !d_bor_passes(sensed.d_bor, d_bor(template), self.config.tau) {
                return (k, Score::Rejected);
            }
            match sensed.correlator.correlation(template, scratch) {
                // Centroid alignment moves the template, hence the target
                // origin, by (sensor centre - template centre).
                Some((c, template_centre)) => {
                    (k, Score::Scored(c, at + sensed.centre - template_centre))
                }
                None => (k, Score::Empty),
            }
        };
        match self.config.threads {
            Threads::Single => {
                let (mut template, mut scratch) = (Vec::new(), Vec::new());
                jobs.iter()
                    .map(|job| one(job, &mut template, &mut scratch))
                    .collect()
            }
            Threads::All => jobs
                .par_iter()
                .map_init(
                    || (Vec::new(), Vec::new()),
                    |(template, scratch), job| one(job, template, scratch),
                )
                .collect(),
        }
    }
}

/// Half the diagonal of the bounding box of `points` (m).
fn bounding_radius(points: &[Vector3<f64>]) -> f64 {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    0.5 * (hi - lo).norm()
}

/// The scored templates sorted by C (ties by grid index).
fn rank(scores: &[(usize, Score)]) -> Vec<Ranked> {
    let mut ranked: Vec<Ranked> = scores
        .iter()
        .filter_map(|&(k, s)| match s {
            Score::Scored(c, origin) => Some((k, c, origin)),
            _ => None,
        })
        .collect();
    ranked.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    ranked
}

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

#[cfg(test)]
#[path = "matcher_tests.rs"]
mod tests;

/// An evenly strided subsample of about `max_points` of `cloud` (all of it
/// when `max_points` is 0 or the cloud is no larger).
fn strided(cloud: &[Point], max_points: usize) -> Vec<Point> {
    let stride = if max_points > 0 && cloud.len() > max_points {
        cloud.len().div_ceil(max_points)
    } else {
        1
    };
    cloud.iter().step_by(stride).copied().collect()
}
