//! From scored candidates to a closed group and one twin per class (see the
//! method in [`crate::symmetry`]).

use nalgebra::Rotation3;

use super::axes::Candidate;
use super::confirm::{Errors, Scorer, Screen};
use super::group::{
    accounted_for, angle_between, class_representative, generate, midpoint, nearest, position,
};
use super::options::{CandidateScore, MAX_TWINS, SymmetryOptions, Verdict};

/// The group, the twins and the score of every candidate.
pub(crate) struct Classified {
    /// The group, the identity first.
    pub(crate) group: Vec<Rotation3<f64>>,
    /// One twin per class, best first.
    pub(crate) twins: Vec<Rotation3<f64>>,
    /// One score per candidate, in the candidates' order.
    pub(crate) scores: Vec<CandidateScore>,
}

/// Outcome of the symmetry stage.
enum Stage {
    /// Decided.
    Settled(Verdict),
    /// Goes on to the twin stage; `confirmed` when it passed the full
    /// symmetry check but could not join a finite group.
    ToTwins { confirmed: bool },
}

/// The group and twins being built.
struct Builder<'a> {
    scorer: &'a Scorer<'a>,
    generators: Vec<Rotation3<f64>>,
    group: Vec<Rotation3<f64>>,
    twins: Vec<Rotation3<f64>>,
    same: f64,
    twin_same: f64,
    max_order: u32,
    cap: usize,
}

impl Builder<'_> {
    /// Symmetry stage for a candidate whose first look found it symmetric.
    /// It joins the group if the group it then generates stays finite (at
    /// most `cap` elements, orders at most `max_order`, checked first as it
    /// costs no distance query) and it and each new element pass the full
    /// symmetry check (`errors` become those of that check).
    fn symmetry_stage(&mut self, r: &Rotation3<f64>, errors: &mut Errors) -> Stage {
        if position(&self.group, r, self.same).is_some() {
            return Stage::Settled(Verdict::Symmetry);
        }
        let mut generators = self.generators.clone();
        generators.push(*r);
        let Some(group) = generate(&generators, self.max_order, self.same, self.cap) else {
            return Stage::ToTwins { confirmed: false };
        };
        let (ok, full) = self.scorer.confirm_symmetry(r);
        *errors = full;
        if !ok {
            return Stage::ToTwins { confirmed: false };
        }
        let new_ok = group
            .iter()
            .filter(|g| position(&self.group, g, self.same).is_none())
            .filter(|g| angle_between(g, r) >= self.same)
            .all(|g| self.scorer.confirm_symmetry(g).0);
        if !new_ok {
            return Stage::ToTwins { confirmed: true };
        }
        self.generators = generators;
        self.group = group;
        Stage::Settled(Verdict::Symmetry)
    }

    /// Twin stage. `confirmed` when the rotation already passed the full
    /// symmetry check (it could not join a finite group).
    /// `screen_mean` is its mean error on the first look.
    fn twin_stage(
        &mut self,
        r: &Rotation3<f64>,
        confirmed: bool,
        screen_mean: f64,
        errors: &mut Errors,
    ) -> Verdict {
        if position(&self.group, r, self.same).is_some() {
            return Verdict::Symmetry;
        }
        if accounted_for(r, &self.twins, &self.group, self.twin_same)
            || !self.separated(r, screen_mean)
        {
            return Verdict::Covered;
        }
        if self.twins.len() >= MAX_TWINS {
            return Verdict::Skipped;
        }
        let accepted = confirmed || {
            let (ok, full) = self.scorer.confirm_twin(r);
            *errors = full;
            ok
        };
        if !accepted {
            return Verdict::Rejected;
        }
        self.twins.push(class_representative(r, &self.group));
        Verdict::Twin
    }

    /// Whether `r` is a pose of its own rather than a slightly-off version
    /// of a group element or listed twin: halfway from the nearest of those
    /// to `r`, the surface fits worse (mean error larger by more than the
    /// tolerance) than at `r` (whose mean error on the same samples is
    /// `mean`).
    fn separated(&self, r: &Rotation3<f64>, mean: f64) -> bool {
        let near = nearest(r, &self.twins, &self.group);
        let between = self.scorer.mean_error(&midpoint(&near, r));
        between > mean + self.scorer.tolerance
    }
}

/// Screens every candidate, then confirms the symmetric ones in order of
/// their error (each joins the group if the group stays finite and
/// confirmed), then the rest, in order of their mean error, as twins.
pub(crate) fn classify(
    candidates: &[Candidate],
    scorer: &Scorer<'_>,
    options: &SymmetryOptions,
) -> Classified {
    let rotations: Vec<Rotation3<f64>> = candidates.iter().map(Candidate::rotation).collect();
    let screened: Vec<(Screen, Errors)> = rotations.iter().map(|r| scorer.screen(r)).collect();
    let mut errors: Vec<Errors> = screened.iter().map(|s| s.1).collect();
    let mut verdicts = vec![Verdict::Rejected; candidates.len()];
    let mut confirmed = vec![false; candidates.len()];
    let mut builder = Builder {
        scorer,
        generators: Vec::new(),
        group: vec![Rotation3::identity()],
        twins: Vec::new(),
        same: options.tolerance_fraction,
        twin_same: options.twin_fraction,
        max_order: options.max_order,
        cap: (2 * options.max_order as usize).max(60),
    };
    let mut pool: Vec<usize> = Vec::new();
    for i in sorted_by(&screened, Screen::Symmetric, |e| e.max) {
        match builder.symmetry_stage(&rotations[i], &mut errors[i]) {
            Stage::Settled(v) => verdicts[i] = v,
            Stage::ToTwins { confirmed: c } => {
                confirmed[i] = c;
                pool.push(i);
            }
        }
    }
    pool.extend(sorted_by(&screened, Screen::Twin, |e| e.max));
    pool.sort_by(|&i, &j| {
        let (a, b) = (&errors[i], &errors[j]);
        a.mean.total_cmp(&b.mean).then(a.max.total_cmp(&b.max))
    });
    for i in pool {
        verdicts[i] = builder.twin_stage(
            &rotations[i],
            confirmed[i],
            screened[i].1.mean,
            &mut errors[i],
        );
    }
    Classified {
        scores: scores(candidates, &errors, &verdicts),
        group: builder.group,
        twins: builder.twins,
    }
}

/// Indices of the candidates whose first look is `which`, by increasing `f`.
fn sorted_by(
    screened: &[(Screen, Errors)],
    which: Screen,
    f: impl Fn(&Errors) -> f64,
) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..screened.len())
        .filter(|&i| screened[i].0 == which)
        .collect();
    idx.sort_by(|&i, &j| f(&screened[i].1).total_cmp(&f(&screened[j].1)));
    idx
}

fn scores(
    candidates: &[Candidate],
    errors: &[Errors],
    verdicts: &[Verdict],
) -> Vec<CandidateScore> {
    candidates
        .iter()
        .zip(errors)
        .zip(verdicts)
        .map(|((c, e), &verdict)| CandidateScore {
            axis: c.axis.into_inner(),
            angle_deg: c.angle.to_degrees(),
            max_error_m: e.max,
            median_error_m: e.median,
            quantile_error_m: e.quantile,
            points: e.points,
            verdict,
        })
        .collect()
}
