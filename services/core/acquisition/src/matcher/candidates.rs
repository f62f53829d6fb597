//! The candidates handed to ICP: the best distinct templates, re-centred,
//! placed by the translation vote and optionally screened by a short ICP.

use super::density::Density;
use super::{TemplateMatcher, strided};
use crate::correlation::Centering;
use crate::refine::screen;
use crate::translation_vote::{VoteScratch, vote_translation};
use crate::visibility::SensedTree;
use nalgebra::{Rotation3, Vector3};
use spacepose_geometry::{Point, Pose, so3};

/// Points of the sensed cloud and of the template in a translation vote
/// (150 × 150 votes).
const VOTE_POINTS: usize = 150;

impl TemplateMatcher {
    /// The candidates to refine, `(grid index, template pose)`, the poses
    /// their refinement starts from, and how many were screened: the
    /// `icp_candidates` best distinct templates, or with screening the
    /// `icp_candidates` best after the short ICP (re-ranked by the reverse
    /// check, see `screen_rerank`), from where it left them.
    pub(super) fn screened_candidates(
        &self,
        density: &Density,
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
                let origin = self.recentre(density, &r, origin, centre, centering);
                (k, Pose::new(r, self.vote(density, &r, origin, positions)))
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
                s.0 += c.unexplained_weight_m2 * self.unexplained(density, sensed, &s.2);
            }
            screened.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        screened.truncate(keep);
        let chosen = screened.iter().map(|&(_, i, _)| templates[i]).collect();
        let starts = screened.iter().map(|&(_, _, p)| p).collect();
        (chosen, starts, templates.len())
    }

    /// The target origin of attitude `r` re-centred `recentre_iterations`
    /// times: the template is rendered with the origin at `origin`, and the
    /// origin moves by the sensor centre minus that template's centre.
    /// Templates are scored rendered at the sensor centroid, and when the
    /// field of view clips the target that render shows another part than
    /// the sensor saw, so its alignment leaves the origin metres off; each
    /// re-render clips like the sensor did.
    pub(super) fn recentre(
        &self,
        density: &Density,
        r: &Rotation3<f64>,
        mut origin: Vector3<f64>,
        centre: &Vector3<f64>,
        centering: Centering,
    ) -> Vector3<f64> {
        let (mut template, mut scratch) = (Vec::new(), Vec::new());
        for _ in 0..self.config.recentre_iterations {
            density.renderer.render_into(r, &origin, &mut template);
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
    pub(super) fn vote(
        &self,
        density: &Density,
        r: &Rotation3<f64>,
        origin: Vector3<f64>,
        positions: &[Vector3<f64>],
    ) -> Vector3<f64> {
        let bin = self.config.translation_vote_bin_m;
        if bin <= 0.0 {
            return origin;
        }
        let template = density.renderer.render(r, &origin);
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
}
