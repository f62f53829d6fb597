//! The twin check of template matching (not in seed 002; the CNN has its
//! own in `spacepose-cnn`): a target with near-symmetric twins `F` (a
//! package's `symmetry.twins`, e.g. deos's 60° roll and half-turns, the
//! relay satellite's half-turn) fits a frame that misses the features
//! breaking the symmetry as well at `(R F, t)` as at `(R, t)`. Neither
//! f_CONV nor the reverse check can then tell them apart, and on Mid-40
//! frames such flips were accepted (issue 24: 9 of the 21 false accepts of
//! the development runs were half-turns or 60° rolls).
//!
//! The winning refinement's twins are refined from its position (the
//! final stages) and join the candidates; the best by `f_CONV + w · U`
//! wins. Then, for every target: when another hypothesis (a twin, or any
//! candidate more than [`SAME_HYPOTHESIS_DEG`] away) scores within the
//! factor `twin_ambiguity` of the winner, the frame cannot decide between
//! them and the solution is not accepted: the init service tries a later
//! frame, whose view may show the difference.

use super::TemplateMatcher;
use super::density::Density;
use super::refinements::Refinements;
use super::stages::Frame;
use crate::refine::refine_with_stages;
use crate::visibility::SensedTree;
use spacepose_geometry::{Pose, so3};

/// Two refinements closer than this (deg) are the same hypothesis.
pub(super) const SAME_HYPOTHESIS_DEG: f64 = 10.0;

impl TemplateMatcher {
    /// Adds the refinements of the twins of the current winner (see the
    /// module documentation), when the check is on, and records whether
    /// the result is ambiguous.
    pub(super) fn add_twins(
        &self,
        density: &Density,
        refinements: &mut Refinements,
        frame: &Frame,
        sensed: &SensedTree,
    ) {
        let factor = self.config.twin_ambiguity;
        let w = self.config.unexplained_weight_m2;
        if factor <= 0.0 {
            return;
        }
        let Some((i, best)) = refinements.best(w) else {
            return;
        };
        let best = best.t_sensor_target;
        let stages = &self.config.icp_stages_m;
        let final_stages = &stages[stages.len().saturating_sub(1)..];
        for f in self.target.twins() {
            let start = Pose::new(best.rotation * f, best.translation);
            let refined = refine_with_stages(
                &self.icp_model,
                self.stage_model(),
                &frame.finite,
                &start,
                &self.config,
                final_stages,
            );
            let u = match &refined {
                Ok(r) => self.unexplained(density, sensed, &r.t_sensor_target),
                Err(_) => 1.0,
            };
            refinements.push(i, refined.map_err(|e| e.to_string()), u);
        }
        refinements.ambiguous =
            refinements.is_ambiguous(w, factor, SAME_HYPOTHESIS_DEG.to_radians());
    }
}

impl Refinements {
    /// Whether a refinement more than `apart_rad` from the best (by
    /// `f_CONV + w · U`) scores within `factor` times the best score.
    pub(super) fn is_ambiguous(&self, w: f64, factor: f64, apart_rad: f64) -> bool {
        let Some((b, best)) = self.best(w) else {
            return false;
        };
        let best_score = self.score(b, best, w);
        self.successes().any(|(k, r)| {
            k != b
                && so3::distance(&r.t_sensor_target.rotation, &best.t_sensor_target.rotation)
                    > apart_rad
                && self.score(k, r, w) <= factor * best_score
        })
    }
}
