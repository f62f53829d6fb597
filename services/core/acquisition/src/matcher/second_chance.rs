//! The second chance of a rejected pose (see
//! [`crate::TemplateMatchingConfig::revote`]): half-turn flips placed again
//! by the translation vote, and the slide search along the principal axis.

use super::density::Density;
use super::{TemplateMatcher, strided};
use crate::refine::{Refined, refine_with_stages, screen};
use crate::slide_search::{SLIDE_STEP_M, principal_axis, slide_poses};
use crate::visibility::SensedTree;
use nalgebra::{Rotation3, Vector3};
use spacepose_geometry::{Point, Pose};
use std::f64::consts::PI;

impl TemplateMatcher {
    /// The second chance of a rejected pose (see
    /// [`TemplateMatchingConfig::revote`] and `revote_flips`): each
    /// attitude tried, with its result and unexplained fraction.
    ///
    /// [`TemplateMatchingConfig::revote`]: crate::TemplateMatchingConfig::revote
    pub(super) fn second_chance(
        &self,
        density: &Density,
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
                self.revote(density, &pose, cloud, positions, sensed)
            })
            .chain(self.slide(density, rejected, cloud, positions, sensed))
            .collect()
    }

    /// The slide search of the second chance (see
    /// [`TemplateMatchingConfig::slide_reach_m`]): the rejected pose moved
    /// along the sensed cloud's principal axis by every
    /// [`SLIDE_STEP_M`] within the reach, each screened by a short ICP
    /// (see [`screen`]); the best, if it scores better than the unmoved
    /// pose, is refined from the final stage on. `None` when the search is
    /// off, finds nothing better, or the refinement fails.
    ///
    /// [`TemplateMatchingConfig::slide_reach_m`]: crate::TemplateMatchingConfig::slide_reach_m
    pub(super) fn slide(
        &self,
        density: &Density,
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
        let u = self.unexplained(density, sensed, &again.t_sensor_target);
        Some((again, u))
    }

    /// One attempt of the second chance: the attitude of `rejected`, placed
    /// by a translation vote from its refined position, refined again
    /// through every stage. `None` when the vote is off or the refinement
    /// fails; else the result and its unexplained fraction.
    pub(super) fn revote(
        &self,
        density: &Density,
        rejected: &Pose,
        cloud: &[Point],
        positions: &[Vector3<f64>],
        sensed: &SensedTree,
    ) -> Option<(Refined, f64)> {
        if self.config.translation_vote_bin_m <= 0.0 {
            return None;
        }
        let r = rejected.rotation;
        let origin = self.vote(density, &r, rejected.translation, positions);
        let again = refine_with_stages(
            &self.icp_model,
            self.stage_model(),
            cloud,
            &Pose::new(r, origin),
            &self.config,
            &self.config.icp_stages_m,
        )
        .ok()?;
        let u = self.unexplained(density, sensed, &again.t_sensor_target);
        Some((again, u))
    }
}
