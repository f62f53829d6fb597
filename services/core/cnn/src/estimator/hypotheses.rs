//! The refinement stage of one estimate (§III.E with the f_CONV check of
//! seed 002 §4.5): the attitude hypotheses of the network's output refined
//! in turn, the twin check on the best, and its report in the estimate.

use super::estimate::CnnEstimate;
use super::{CnnEstimator, NetworkPose};
use crate::decode::{decode_around, modes};
use crate::refinement::Refined;
use crate::twins::{TwinOutcome, check_twins};
use spacepose_geometry::{Point, Pose};

/// The refinement of the attitude hypotheses of one frame.
pub(super) struct Hypotheses {
    /// The hypothesis index and refinement with the lowest f_CONV (the
    /// first accepted one).
    pub(super) best: Option<(usize, Refined)>,
    /// Hypotheses refined.
    pub(super) tried: usize,
    /// The first refinement error, if any.
    pub(super) error: Option<String>,
}

impl CnnEstimator {
    /// Refines the attitude hypotheses of `net` on `cloud` (§III.E, with
    /// the f_CONV check), then runs the twin check on the best refinement
    /// (which it may replace); the default outcome when none succeeded.
    pub(super) fn refine_and_check_twins(
        &self,
        cloud: &[Point],
        net: &NetworkPose,
    ) -> (Hypotheses, TwinOutcome) {
        let mut refined = self.refine_hypotheses(cloud, &net.raw, &net.probs, net.delta_beta);
        let mut twins = TwinOutcome::default();
        if let Some((h, r)) = refined.best.take() {
            let (r, outcome) = check_twins(&self.refiner, cloud, r, &self.config.twins);
            refined.best = Some((h, r));
            twins = outcome;
        }
        (refined, twins)
    }

    /// Puts the best refinement of `refined` in `estimate` (with its
    /// f_CONV check), or, none having succeeded, the first refinement error.
    pub(super) fn report_refinement(&self, estimate: &mut CnnEstimate, refined: Hypotheses) {
        match refined.best {
            Some((h, r)) => {
                estimate.t_sensor_target = r.t_sensor_target;
                estimate.f_conv_m2 = r.f_conv_m2;
                estimate.accepted = self.refiner.accepts(r.f_conv_m2);
                estimate.hypothesis = h;
                estimate.ndt_iterations = r.ndt_iterations;
                estimate.ndt_converged = r.ndt_converged;
                estimate.fconv_ms = r.fconv_ms;
            }
            None => estimate.refinement_error = refined.error,
        }
    }

    /// Refines Γ_sym's pose, then the other modes of `probs` (same position)
    /// until one passes the f_CONV check; keeps the lowest f_CONV.
    fn refine_hypotheses(
        &self,
        cloud: &[Point],
        raw: &Pose,
        probs: &[f32],
        delta_beta: f64,
    ) -> Hypotheses {
        let mut result = Hypotheses {
            best: None,
            tried: 0,
            error: None,
        };
        let modes = if self.config.hypotheses > 1 {
            modes(&self.classes, probs, self.config.hypotheses, delta_beta)
        } else {
            Vec::new()
        };
        let rotations = std::iter::once(raw.rotation).chain(
            modes
                .into_iter()
                .skip(1)
                .map(|i| decode_around(&self.classes, probs, i, delta_beta)),
        );
        for (h, rotation) in rotations.enumerate() {
            result.tried += 1;
            let pose = Pose {
                rotation,
                translation: raw.translation,
            };
            match self.refiner.refine(cloud, &pose) {
                Ok(r) => {
                    let accepted = self.refiner.accepts(r.f_conv_m2);
                    if result
                        .best
                        .as_ref()
                        .is_none_or(|(_, b)| r.f_conv_m2 < b.f_conv_m2)
                    {
                        result.best = Some((h, r));
                    }
                    if accepted {
                        break;
                    }
                }
                Err(e) => {
                    result.error.get_or_insert(e.to_string());
                }
            }
        }
        result
    }
}
