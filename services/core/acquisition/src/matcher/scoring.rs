//! Template matching proper (seed 002 §2): every grid attitude's template
//! rendered and scored by C of Eq. (1) against the sensed cloud, with the
//! Eq. (3) pre-check and the optional coarse-to-fine pass.

use super::TemplateMatcher;
use super::density::Density;
use crate::config::Threads;
use crate::correlation::{Correlator, d_bor, d_bor_passes};
use crate::template::TemplateRenderer;
use nalgebra::Vector3;
use rayon::prelude::*;

/// How one template fared.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Score {
    /// Fewer than 3 points (the target out of the field of view).
    Empty,
    /// Rejected by Eq. (3).
    Rejected,
    /// C of Eq. (1) and the target origin it implies (sensor frame): the
    /// render position moved by the centroid alignment.
    Scored(f64, Vector3<f64>),
}

/// A scored template: grid index, C, implied target origin.
pub(super) type Ranked = (usize, f64, Vector3<f64>);

/// Per-acquisition inputs shared by every template evaluation.
pub(super) struct Sensed<'a> {
    /// The density level of the frame (its template renderers).
    pub(super) density: &'a Density,
    pub(super) correlator: &'a Correlator,
    pub(super) centre: Vector3<f64>,
    pub(super) d_bor: f64,
}

impl TemplateMatcher {
    /// Renders and scores the templates: `(grid index, C, implied origin)`
    /// sorted by C, templates generated, templates rejected by Eq. (3).
    pub(super) fn match_templates(&self, sensed: &Sensed) -> (Vec<Ranked>, usize, usize) {
        let all: Vec<(usize, Vector3<f64>)> =
            (0..self.grid.len()).map(|k| (k, sensed.centre)).collect();
        let renderer = &sensed.density.renderer;
        let (first, fine) = match (&sensed.density.coarse, self.config.coarse_to_fine) {
            (Some(coarse), Some(c)) => (coarse, Some(c.keep)),
            _ => (renderer, None),
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
            let scores = self.score(&kept, renderer, sensed, false);
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
    pub(super) fn score(
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
