//! Committed `eval tracking` runs (the JSON `--json` writes, series kept
//! to each frame's status and errors) pooled over seeds per scenario and
//! mode: the Monte-Carlo statistics the results tables print.

use crate::tracking::{DIVERGED_DEG, DIVERGED_M};
use anyhow::{Context, Result};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

/// One frame of a run: what the scoring needs.
#[derive(Debug, Clone, Deserialize)]
pub struct FrameErr {
    /// Frame index.
    pub frame: usize,
    /// `tracking`, `degraded` or `lost`.
    pub status: String,
    /// Angular error (deg; null when nothing was published).
    pub ang_err_deg: Option<f64>,
    /// Position error (cm; null when nothing was published).
    pub pos_err_cm: Option<f64>,
}

impl FrameErr {
    /// More than 10° or 50 cm off in truth, or without a pose.
    pub fn far_off(&self) -> bool {
        !(self.ang_err_deg.is_some_and(|a| a <= DIVERGED_DEG)
            && self.pos_err_cm.is_some_and(|p| p <= DIVERGED_M * 100.0))
    }
}

/// One mode of a run.
#[derive(Debug, Clone, Deserialize)]
pub struct ModeRun {
    /// Its frames.
    pub series: Vec<FrameErr>,
}

/// One `eval tracking --json` run.
#[derive(Debug, Clone, Deserialize)]
pub struct Run {
    /// Scenario name.
    pub scenario: String,
    /// Target name.
    pub target: String,
    /// Seed.
    pub seed: u64,
    /// Frames excluded from the converged statistics.
    pub warmup: usize,
    /// Modes by name.
    pub modes: BTreeMap<String, ModeRun>,
}

/// Every `*.json` run of `dir`, sorted by scenario and seed.
pub fn load_dir(dir: &Path) -> Result<Vec<Run>> {
    let mut runs = Vec::new();
    let entries = std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))?;
    for entry in entries {
        let path = entry?.path();
        if path.extension().is_some_and(|e| e == "json") {
            let text = std::fs::read_to_string(&path)
                .with_context(|| format!("reading {}", path.display()))?;
            let run: Run = serde_json::from_str(&text)
                .with_context(|| format!("parsing {}", path.display()))?;
            runs.push(run);
        }
    }
    runs.sort_by(|a, b| (&a.scenario, a.seed).cmp(&(&b.scenario, b.seed)));
    Ok(runs)
}

/// One scenario and mode over every seed: errors of the frames after each
/// run's warm-up, pooled.
#[derive(Debug, Clone, PartialEq)]
pub struct Pooled {
    /// Seeds (runs) pooled.
    pub seeds: usize,
    /// Frames after the warm-up.
    pub frames: usize,
    /// Median, 95th percentile and maximum of the angular error (deg) of
    /// the frames with a published pose.
    pub ang_deg: [f64; 3],
    /// The same of the position error (cm).
    pub pos_cm: [f64; 3],
    /// Frames reported lost.
    pub lost: usize,
    /// Frames whose true error exceeds 10° or 50 cm, or lost.
    pub diverged: usize,
    /// Diverged frames the tracker published as `tracking`: silent
    /// divergences.
    pub silent: usize,
}

/// Scenario (or target) → mode → pooled statistics.
pub type Pools = BTreeMap<String, BTreeMap<String, Pooled>>;

/// Pools `runs` by scenario and mode.
pub fn pool(runs: &[Run]) -> Pools {
    pool_by(runs, |r| r.scenario.clone())
}

/// Pools `runs` by `key` (e.g. the target) and mode.
pub fn pool_by(runs: &[Run], key: impl Fn(&Run) -> String) -> Pools {
    let mut frames: BTreeMap<(String, String), (usize, Vec<FrameErr>)> = BTreeMap::new();
    for run in runs {
        for (mode, m) in &run.modes {
            let entry = frames.entry((key(run), mode.clone())).or_default();
            entry.0 += 1;
            let after = m.series.iter().filter(|f| f.frame >= run.warmup).cloned();
            entry.1.extend(after);
        }
    }
    let mut pools = Pools::new();
    for ((scenario, mode), (seeds, series)) in frames {
        pools
            .entry(scenario)
            .or_default()
            .insert(mode, pooled(seeds, &series));
    }
    pools
}

fn pooled(seeds: usize, series: &[FrameErr]) -> Pooled {
    let published = |f: &&FrameErr| f.status != "lost";
    let ang: Vec<f64> = series
        .iter()
        .filter(published)
        .filter_map(|f| f.ang_err_deg)
        .collect();
    let pos: Vec<f64> = series
        .iter()
        .filter(published)
        .filter_map(|f| f.pos_err_cm)
        .collect();
    let is_diverged = |f: &FrameErr| f.status == "lost" || f.far_off();
    Pooled {
        seeds,
        frames: series.len(),
        ang_deg: quantiles(&ang),
        pos_cm: quantiles(&pos),
        lost: series.iter().filter(|f| f.status == "lost").count(),
        diverged: series.iter().filter(|f| is_diverged(f)).count(),
        silent: series
            .iter()
            .filter(|f| f.status == "tracking" && is_diverged(f))
            .count(),
    }
}

/// Median, 95th percentile (nearest rank) and maximum of the finite
/// values; NaN when there is none.
pub fn quantiles(values: &[f64]) -> [f64; 3] {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return [f64::NAN; 3];
    }
    v.sort_by(f64::total_cmp);
    let rank = |q: f64| v[((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1];
    [rank(0.5), rank(0.95), v[v.len() - 1]]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(frame: usize, status: &str, ang: Option<f64>, pos: Option<f64>) -> FrameErr {
        FrameErr {
            frame,
            status: status.into(),
            ang_err_deg: ang,
            pos_err_cm: pos,
        }
    }

    #[test]
    fn quantiles_are_nearest_ranks_of_the_finite_values() {
        let v: Vec<f64> = (1..=20).map(f64::from).chain([f64::NAN]).collect();
        assert_eq!(quantiles(&v), [10.0, 19.0, 20.0]);
        assert!(quantiles(&[]).iter().all(|q| q.is_nan()));
    }

    #[test]
    fn pooling_skips_the_warm_up_and_counts_silent_divergences() {
        let series = vec![
            frame(0, "tracking", Some(50.0), Some(1.0)),
            frame(1, "tracking", Some(1.0), Some(2.0)),
            frame(2, "tracking", Some(12.0), Some(2.0)),
            frame(3, "degraded", Some(2.0), Some(60.0)),
            frame(4, "lost", None, None),
        ];
        let run = Run {
            scenario: "tumbling".into(),
            target: "deos".into(),
            seed: 1,
            warmup: 1,
            modes: BTreeMap::from([("ndt".to_string(), ModeRun { series })]),
        };
        let pools = pool(&[run.clone(), Run { seed: 2, ..run }]);
        let p = &pools["tumbling"]["ndt"];
        assert_eq!((p.seeds, p.frames, p.lost), (2, 8, 2));
        // Frames 2 (12°), 3 (60 cm) and 4 (lost) of both seeds diverged;
        // only frame 2 was published as tracking.
        assert_eq!((p.diverged, p.silent), (6, 2));
        assert_eq!(p.ang_deg[2], 12.0);
        assert_eq!(p.pos_cm[2], 60.0);
    }
}
