//! The ICP refinements of one frame's candidates and how the solution is
//! chosen among them.

use crate::refine::Refined;
use spacepose_geometry::Pose;

/// The ICP refinements of one frame's candidates; `candidates`, `refined`
/// and `unexplained` are index-aligned (index = rank).
pub(super) struct Refinements {
    /// `(grid index, template pose)` of each refinement.
    pub(super) candidates: Vec<(usize, Pose)>,
    /// The refinement results (errors as their messages).
    pub(super) refined: Vec<Result<Refined, String>>,
    /// Unexplained fraction of each result (1 for a failed refinement).
    pub(super) unexplained: Vec<f64>,
    /// Candidates screened by a short ICP (0 when screening is off).
    pub(super) screened: usize,
    /// Another hypothesis fits about as well as the best (see the
    /// matcher's `twins` module): the solution is not accepted.
    pub(super) ambiguous: bool,
}

/// The chosen solution: the winning refinement, or the first candidate's
/// template pose when every refinement failed.
pub(super) struct Chosen {
    /// Index of the winning candidate in [`Refinements`].
    pub(super) rank: usize,
    /// The refined pose (the template pose if every refinement failed).
    pub(super) pose: Pose,
    /// f_CONV (m²), infinite if every refinement failed.
    pub(super) f_conv_m2: f64,
    /// ICP iterations over all stages.
    pub(super) iterations: usize,
    /// The final ICP stage converged.
    pub(super) converged: bool,
    /// Inlier fraction of the final ICP stage.
    pub(super) inlier_fraction: f64,
    /// Unexplained fraction, 1 if every refinement failed.
    pub(super) unexplained_fraction: f64,
    /// The first candidate's refinement error if every refinement failed.
    pub(super) refinement_error: Option<String>,
}

impl Refinements {
    /// The successful refinement with the lowest score (see
    /// [`Refinements::score`]): `(index, result)`; the first of equals.
    pub(super) fn best(&self, w: f64) -> Option<(usize, &Refined)> {
        self.successes()
            .min_by(|a, b| self.score(a.0, a.1, w).total_cmp(&self.score(b.0, b.1, w)))
    }

    /// The score of refinement `i`: its uncapped f_CONV plus `w` times its
    /// unexplained fraction (in [0, 1], so `w = 0` ranks by f_CONV alone).
    pub(super) fn score(&self, i: usize, r: &Refined, w: f64) -> f64 {
        r.msd_all_m2 + w * self.unexplained[i]
    }

    /// The successful refinements with their indices.
    pub(super) fn successes(&self) -> impl Iterator<Item = (usize, &Refined)> {
        self.refined
            .iter()
            .enumerate()
            .filter_map(|(i, r)| r.as_ref().ok().map(|r| (i, r)))
    }

    /// Appends a refinement of candidate `i`'s template.
    pub(super) fn push(&mut self, i: usize, refined: Result<Refined, String>, unexplained: f64) {
        self.refined.push(refined);
        self.unexplained.push(unexplained);
        self.candidates.push(self.candidates[i]);
    }

    /// The chosen solution (see [`Refinements::best`], weight `w`); when
    /// every refinement failed, the first candidate's template pose with
    /// f_CONV infinite, unexplained fraction 1 and the first error.
    pub(super) fn choose(&self, w: f64) -> Chosen {
        match self.best(w) {
            Some((i, r)) => Chosen {
                rank: i,
                pose: r.t_sensor_target,
                f_conv_m2: r.f_conv_m2,
                iterations: r.iterations,
                converged: r.converged,
                inlier_fraction: r.inlier_fraction,
                unexplained_fraction: self.unexplained[i],
                refinement_error: None,
            },
            None => Chosen {
                rank: 0,
                pose: self.candidates[0].1,
                f_conv_m2: f64::INFINITY,
                iterations: 0,
                converged: false,
                inlier_fraction: 0.0,
                unexplained_fraction: 1.0,
                refinement_error: self.refined.first().and_then(|r| r.as_ref().err().cloned()),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Vector3};

    fn refined(angle_deg: f64, msd_m2: f64) -> Result<Refined, String> {
        let r = Rotation3::from_axis_angle(&Vector3::x_axis(), angle_deg.to_radians());
        Ok(Refined {
            t_sensor_target: Pose::new(r, Vector3::new(0.0, 0.0, 20.0)),
            f_conv_m2: msd_m2,
            msd_all_m2: msd_m2,
            iterations: 10,
            converged: true,
            inlier_fraction: 0.9,
        })
    }

    fn refinements(list: Vec<(f64, f64, f64)>) -> Refinements {
        let n = list.len();
        Refinements {
            candidates: vec![(0, Pose::identity()); n],
            unexplained: list.iter().map(|l| l.2).collect(),
            refined: list.into_iter().map(|(a, m, _)| refined(a, m)).collect(),
            screened: 0,
            ambiguous: false,
        }
    }

    /// A half-turn scoring within 1.5x of the winner is ambiguous; a worse
    /// one, a failed one, or a near copy of the winner is not.
    #[test]
    fn another_hypothesis_within_the_factor_is_ambiguous() {
        let apart = 10f64.to_radians();
        let w = 0.05;
        // Scores 0.001 + 0.05 · 0.02 = 0.002 and 0.0012 + 0.05 · 0.03 = 0.0027.
        let close = refinements(vec![(0.0, 0.001, 0.02), (180.0, 0.0012, 0.03)]);
        assert!(close.is_ambiguous(w, 1.5, apart));
        assert!(!close.is_ambiguous(w, 1.2, apart));
        let worse = refinements(vec![(0.0, 0.001, 0.02), (180.0, 0.004, 0.2)]);
        assert!(!worse.is_ambiguous(w, 1.5, apart));
        let copy = refinements(vec![(0.0, 0.001, 0.02), (4.0, 0.001, 0.02)]);
        assert!(!copy.is_ambiguous(w, 1.5, apart));
        let mut failed = refinements(vec![(0.0, 0.001, 0.02), (180.0, 0.001, 0.02)]);
        failed.refined[1] = Err("diverged".into());
        assert!(!failed.is_ambiguous(w, 1.5, apart));
        // The better of the two wins whichever came first.
        let later = refinements(vec![(180.0, 0.003, 0.1), (0.0, 0.001, 0.02)]);
        assert_eq!(later.best(w).map(|b| b.0), Some(1));
    }
}
