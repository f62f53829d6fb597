//! `spacepose eval tracking --report FILE`: the Monte-Carlo of issue 25.
//! The same evaluation on every seed of a committed list (the blind seeds
//! by default, `crate::seeds`), reduced per seed to the figures a reviewer
//! asks for, and over the seeds to their mean, 95th percentile, maximum and
//! a 95 % confidence interval of the mean. The whole run counts: the
//! start-up is not excluded (the warm-up is reported apart). A figure
//! with no value (NaN: no pose at all) is written as `null`;
//! `crate::tables::monte_carlo` reads the files back.

use super::acquisition::AcquisitionCounts;
use super::nees::NeesSummary;
use super::report::{FrameRecord, TrackingReport};
use anyhow::{Context, Result};
use rayon::prelude::*;
use serde::Serialize;
use spacepose_tracker::TrackStatus;
use std::collections::BTreeMap;

/// One seed's figures for one mode.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SeedFigures {
    /// The scenario and sensor seed.
    pub seed: u64,
    /// Largest angular error over the whole run's published poses, start-up
    /// included (deg; lost frames publish none).
    pub ang_max_deg: f64,
    /// Mean angular error over the same frames (deg).
    pub ang_mean_deg: f64,
    /// Largest angular error after the warm-up (deg).
    pub ang_max_after_warmup_deg: f64,
    /// Mean position error over the published poses (cm).
    pub pos_mean_cm: f64,
    /// Largest position error over the published poses (cm).
    pub pos_max_cm: f64,
    /// Frames reported `lost`.
    pub lost: usize,
    /// Frames reported `degraded`.
    pub degraded: usize,
    /// Frames more than 10° or 50 cm off in truth, or lost.
    pub diverged: usize,
    /// Frames published as `tracking` while more than 10° or 50 cm off.
    pub silent: usize,
    /// Frames published `unconfirmed` (the acquisition awaiting its
    /// confirmation by a second look).
    pub unconfirmed: usize,
    /// Of those, frames more than 10° or 50 cm off.
    pub unconfirmed_far_off: usize,
    /// Acquisitions by verdict (`--init acquire`; zero from the truth).
    pub acquisitions: AcquisitionCounts,
    /// Median NEES of the published poses' covariance (5.3 when
    /// consistent; NaN without a covariance).
    pub nees_median: f64,
    /// Share of those frames above the χ²(6) 95 % bound (0.05 when
    /// consistent).
    pub nees_above_95: f64,
    /// Median NEES of the filter service's posterior with its own
    /// covariance, over the frames it fused (5.3 when consistent).
    pub filter_nees_median: f64,
    /// Share of those frames above the χ²(6) 95 % bound.
    pub filter_nees_above_95: f64,
    /// Median NIS of the registrations against the filter's predictions.
    pub nis_median: f64,
    /// Share of those frames above the χ²(6) 95 % bound.
    pub nis_above_95: f64,
}

/// A figure over the seeds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Spread {
    /// Mean over the seeds.
    pub mean: f64,
    /// 95th percentile (nearest rank).
    pub p95: f64,
    /// Largest.
    pub max: f64,
    /// 95 % confidence interval of the mean (Student's t).
    pub ci95: [f64; 2],
}

/// One mode over every seed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeMonteCarlo {
    /// Per seed, in the list's order.
    pub per_seed: Vec<SeedFigures>,
    /// Each figure of [`SeedFigures`] (by field name) over the seeds.
    pub stats: BTreeMap<String, Spread>,
}

/// The whole Monte-Carlo.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MonteCarloReport {
    /// Scenario name.
    pub scenario: String,
    /// Target name.
    pub target: String,
    /// The seed list's name (`blind`, `development`) or the seeds given.
    pub seed_set: String,
    /// The seeds run.
    pub seeds: Vec<u64>,
    /// Frames per run.
    pub frames: usize,
    /// Warm-up frames (only `ang_max_after_warmup_deg` skips them).
    pub warmup: usize,
    /// A note on the configuration (e.g. a tracker configuration file).
    pub configuration: String,
    /// Results per mode name.
    pub modes: BTreeMap<String, ModeMonteCarlo>,
}

/// Runs `evaluate` (one evaluation of a seed) on every seed of `seeds`
/// (as many at a time as the machine has cores; each run's frames are
/// simulated in parallel too) and reduces the runs.
///
/// The seeds run on a pool of their own, not rayon's global one: a run
/// from init's acquisitions waits (sleeping) for init's worker thread,
/// whose template matching runs on the global pool. With the seeds on the
/// global pool, every worker of it could be such a wait, and the matching
/// would never run (it deadlocked with the facility clutter on, where
/// template matching takes over from the CNN).
pub fn monte_carlo(
    evaluate: impl Fn(u64) -> Result<TrackingReport> + Sync,
    seed_set: &str,
    seeds: &[u64],
    configuration: &str,
) -> Result<MonteCarloReport> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(rayon::current_num_threads())
        .thread_name(|i| format!("monte-carlo-{i}"))
        .build()
        .context("building the Monte-Carlo thread pool")?;
    let runs: Vec<TrackingReport> = pool.install(|| {
        seeds
            .par_iter()
            .map(|&seed| {
                let run = evaluate(seed);
                tracing::info!(seed, ok = run.is_ok(), "Monte-Carlo run done");
                run
            })
            .collect::<Result<_>>()
    })?;
    anyhow::ensure!(!runs.is_empty(), "no seed to run");
    let first = &runs[0];
    let mut modes = BTreeMap::new();
    for mode in first.modes.keys() {
        let per_seed: Vec<SeedFigures> = runs
            .iter()
            .map(|r| figures(r.seed, &r.modes[mode].series, r.warmup))
            .collect();
        let stats = spreads(&per_seed);
        modes.insert(mode.clone(), ModeMonteCarlo { per_seed, stats });
    }
    Ok(MonteCarloReport {
        scenario: first.scenario.clone(),
        target: first.target.clone(),
        seed_set: seed_set.to_string(),
        seeds: seeds.to_vec(),
        frames: first.frames,
        warmup: first.warmup,
        configuration: configuration.to_string(),
        modes,
    })
}

/// One run's figures.
pub fn figures(seed: u64, series: &[FrameRecord], warmup: usize) -> SeedFigures {
    let published: Vec<&FrameRecord> = series
        .iter()
        .filter(|r| r.status != TrackStatus::Lost && r.ang_err_deg.is_finite())
        .collect();
    let max = |v: &mut dyn Iterator<Item = f64>| v.fold(f64::NAN, f64::max);
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let ang: Vec<f64> = published.iter().map(|r| r.ang_err_deg).collect();
    let pos: Vec<f64> = published.iter().map(|r| r.pos_err_cm).collect();
    let count = |s: TrackStatus| series.iter().filter(|r| r.status == s).count();
    let nees = NeesSummary::of(series.iter().map(|r| r.nees));
    let filter_nees = NeesSummary::of(series.iter().map(|r| r.filter_nees));
    let nis = NeesSummary::of(series.iter().map(|r| r.nis));
    SeedFigures {
        seed,
        ang_max_deg: max(&mut ang.iter().copied()),
        ang_mean_deg: mean(&ang),
        ang_max_after_warmup_deg: max(&mut published
            .iter()
            .filter(|r| r.frame >= series[0].frame + warmup)
            .map(|r| r.ang_err_deg)),
        pos_mean_cm: mean(&pos),
        pos_max_cm: max(&mut pos.iter().copied()),
        lost: count(TrackStatus::Lost),
        degraded: count(TrackStatus::Degraded),
        diverged: series
            .iter()
            .filter(|r| r.status == TrackStatus::Lost || r.far_off())
            .count(),
        silent: series.iter().filter(|r| r.silent()).count(),
        unconfirmed: count(TrackStatus::Unconfirmed),
        unconfirmed_far_off: series
            .iter()
            .filter(|r| r.status == TrackStatus::Unconfirmed && r.far_off())
            .count(),
        acquisitions: AcquisitionCounts::of(series.iter().filter_map(|r| r.acquisition.as_ref())),
        nees_median: nees.median_or_nan(),
        nees_above_95: nees.above_95_or_nan(),
        filter_nees_median: filter_nees.median_or_nan(),
        filter_nees_above_95: filter_nees.above_95_or_nan(),
        nis_median: nis.median_or_nan(),
        nis_above_95: nis.above_95_or_nan(),
    }
}

/// Every figure over the seeds. A NaN figure (a run with no pose at all)
/// makes its spread NaN rather than vanish.
fn spreads(per_seed: &[SeedFigures]) -> BTreeMap<String, Spread> {
    let column = |f: fn(&SeedFigures) -> f64| per_seed.iter().map(f).collect::<Vec<_>>();
    let columns: [(&str, Vec<f64>); 18] = [
        ("ang_max_deg", column(|s| s.ang_max_deg)),
        ("ang_mean_deg", column(|s| s.ang_mean_deg)),
        (
            "ang_max_after_warmup_deg",
            column(|s| s.ang_max_after_warmup_deg),
        ),
        ("pos_mean_cm", column(|s| s.pos_mean_cm)),
        ("pos_max_cm", column(|s| s.pos_max_cm)),
        ("lost", column(|s| s.lost as f64)),
        ("degraded", column(|s| s.degraded as f64)),
        ("diverged", column(|s| s.diverged as f64)),
        ("silent", column(|s| s.silent as f64)),
        ("acquired", column(|s| s.acquisitions.correct as f64)),
        (
            "false_accepts",
            column(|s| s.acquisitions.false_accepts as f64),
        ),
        ("rejected", column(|s| s.acquisitions.rejected as f64)),
        ("nees_median", column(|s| s.nees_median)),
        ("nees_above_95", column(|s| s.nees_above_95)),
        ("filter_nees_median", column(|s| s.filter_nees_median)),
        ("filter_nees_above_95", column(|s| s.filter_nees_above_95)),
        ("nis_median", column(|s| s.nis_median)),
        ("nis_above_95", column(|s| s.nis_above_95)),
    ];
    columns
        .into_iter()
        .map(|(name, v)| (name.to_string(), spread(&v)))
        .collect()
}

/// Mean, p95 (nearest rank), max and the 95 % confidence interval of the
/// mean of `v` (NaN throughout when a value is NaN or `v` is empty).
pub fn spread(v: &[f64]) -> Spread {
    let nan = Spread {
        mean: f64::NAN,
        p95: f64::NAN,
        max: f64::NAN,
        ci95: [f64::NAN; 2],
    };
    if v.is_empty() || v.iter().any(|x| x.is_nan()) {
        return nan;
    }
    let n = v.len();
    let mean = v.iter().sum::<f64>() / n as f64;
    let mut sorted = v.to_vec();
    sorted.sort_by(f64::total_cmp);
    let rank = ((0.95 * n as f64).ceil() as usize).clamp(1, n);
    let half = if n > 1 {
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        t975(n - 1) * (var / n as f64).sqrt()
    } else {
        f64::INFINITY
    };
    Spread {
        mean,
        p95: sorted[rank - 1],
        max: sorted[n - 1],
        ci95: [mean - half, mean + half],
    }
}

/// Student's t 97.5 % quantile for `dof` degrees of freedom: tabulated to
/// 30, then the value at the start of each range (never narrower).
fn t975(dof: usize) -> f64 {
    const T: [f64; 30] = [
        12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160,
        2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056,
        2.052, 2.048, 2.045, 2.042,
    ];
    match dof {
        0 => f64::INFINITY,
        1..=30 => T[dof - 1],
        d if d <= 60 => 2.042,
        d if d <= 120 => 2.000,
        _ => 1.980,
    }
}

#[cfg(test)]
#[path = "monte_carlo_tests.rs"]
mod tests;
