//! The twin check (not in seed 004): a refined pose `(R, t)` of a target
//! with near-symmetric twins `F` ([`spacepose_model::Target::twins`]:
//! deos' tower at the other end, its bars on the empty edges) fits the
//! points as well as the twin pose `(R F, t)` wherever the view misses the
//! features that break the symmetry, so f_CONV cannot tell them apart: on
//! `spacepose eval cnn --seed 1001` the CNN's 180° and 60° flips pass it
//! with the same f_CONV as the successes.
//!
//! The check casts each refined point's ray against the model at `(R, t)`
//! and at every `(R F, t)` ([`spacepose_model::consistency`]). When a
//! twin explains more points (the tower seen where the pose has none, or
//! the pose's tower standing before a surface the sensor saw through),
//! the twin is refined like the estimate and replaces it if it explains
//! more points after its refinement and passes f_CONV. A frame whose own
//! pose explains the most costs only the ray casts.

use nalgebra::Vector3;
use spacepose_geometry::{Point, Pose};

use crate::refinement::{Refined, Refiner};

/// Twin check settings.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TwinCheckConfig {
    /// Run the check (when the target declares twins).
    pub enabled: bool,
    /// A twin is refined when it explains more than this fraction of the
    /// points beyond the estimate.
    pub margin: f64,
    /// At most this many of the refined points are cast (every k-th).
    pub max_rays: usize,
}

impl Default for TwinCheckConfig {
    fn default() -> Self {
        Self {
            enabled: true,
            margin: 0.0,
            max_rays: 1000,
        }
    }
}

/// What the check did.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct TwinOutcome {
    /// Fraction of the points the estimate explains.
    pub explained: f64,
    /// The best twin's fraction (unrefined), if the target has twins.
    pub best_twin_explained: Option<f64>,
    /// Twins refined (those explaining more than the estimate).
    pub twins_refined: usize,
    /// The twin whose refinement replaced the estimate, if one did.
    pub twin: Option<usize>,
}

/// Checks `estimate` (a refinement of `cloud`) against the target's twins;
/// returns the pose to report and what was done.
pub fn check_twins(
    refiner: &Refiner,
    cloud: &[Point],
    estimate: Refined,
    config: &TwinCheckConfig,
) -> (Refined, TwinOutcome) {
    let rays = every_kth(&estimate.sensed, config.max_rays);
    let explained = |pose: &Pose| refiner.consistency(&rays, pose).explained_fraction();
    let rigid = estimate.t_sensor_target_rigid;
    let mut outcome = TwinOutcome {
        explained: explained(&rigid),
        ..TwinOutcome::default()
    };
    if !config.enabled || refiner.twins().is_empty() {
        return (estimate, outcome);
    }
    let scored: Vec<(usize, f64)> = refiner
        .twins()
        .iter()
        .map(|f| explained(&Pose::new(rigid.rotation * f, rigid.translation)))
        .enumerate()
        .collect();
    outcome.best_twin_explained = scored.iter().map(|s| s.1).max_by(f64::total_cmp);
    // Every twin that explains more is refined; the refinement explaining
    // the most (and passing f_CONV) wins, the estimate staying on a tie.
    let mut best: Option<(usize, f64, Refined)> = None;
    for &(i, e) in &scored {
        if e <= outcome.explained + config.margin {
            continue;
        }
        outcome.twins_refined += 1;
        let twin = Pose::new(rigid.rotation * refiner.twins()[i], rigid.translation);
        let Ok(refined) = refiner.refine(cloud, &twin) else {
            continue;
        };
        let e = explained(&refined.t_sensor_target_rigid);
        let beats = best.as_ref().map_or(outcome.explained, |b| b.1);
        if e > beats && refiner.accepts(refined.f_conv_m2) {
            best = Some((i, e, refined));
        }
    }
    match best {
        Some((i, _, refined)) => {
            outcome.twin = Some(i);
            (refined, outcome)
        }
        None => (estimate, outcome),
    }
}

/// Every k-th vector so that at most `max` remain (`max == 0`: all).
fn every_kth(v: &[Vector3<f64>], max: usize) -> Vec<Vector3<f64>> {
    if max == 0 || v.len() <= max {
        return v.to_vec();
    }
    v.iter().step_by(v.len().div_ceil(max)).copied().collect()
}

#[cfg(test)]
#[path = "twins_tests.rs"]
mod tests;
