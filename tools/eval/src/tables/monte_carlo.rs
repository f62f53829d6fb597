//! The Monte-Carlo table: every committed `eval tracking --report` file
//! under [`MONTE_CARLO_RUNS`], one row per file and mode.

use anyhow::{Context, Result};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

/// Committed `--report` files.
pub const MONTE_CARLO_RUNS: &str = "docs/results/monte-carlo";

/// A figure over the seeds, as written (`null` for NaN).
#[derive(Debug, Clone, Copy, Deserialize)]
pub struct Spread {
    /// Mean over the seeds.
    pub mean: Option<f64>,
    /// 95th percentile.
    pub p95: Option<f64>,
    /// Largest.
    pub max: Option<f64>,
    /// 95 % confidence interval of the mean.
    pub ci95: [Option<f64>; 2],
}

/// One mode of a report: what the table prints.
#[derive(Debug, Clone, Deserialize)]
pub struct Mode {
    /// Figures over the seeds, by name.
    pub stats: BTreeMap<String, Spread>,
    /// Per-seed figures (only the failure counts are read).
    pub per_seed: Vec<Counts>,
}

/// A seed's failure counts.
#[derive(Debug, Clone, Copy, Deserialize)]
pub struct Counts {
    /// Frames reported lost.
    pub lost: usize,
    /// Frames off in truth, or lost.
    pub diverged: usize,
    /// Frames published as tracking while off.
    pub silent: usize,
    /// Frames published unconfirmed (absent from reports before the
    /// status existed: none could be).
    #[serde(default)]
    pub unconfirmed: usize,
    /// Of those, frames off.
    #[serde(default)]
    pub unconfirmed_far_off: usize,
    /// Acquisitions by verdict (absent from reports started from the truth).
    #[serde(default)]
    pub acquisitions: Acquisitions,
}

/// A seed's acquisitions by verdict.
#[derive(Debug, Clone, Copy, Default, Deserialize)]
pub struct Acquisitions {
    /// Accepted within the far-off bound.
    pub correct: usize,
    /// Accepted beyond it.
    pub false_accepts: usize,
    /// Refused by the checks.
    pub rejected: usize,
}

/// One `--report` file.
#[derive(Debug, Clone, Deserialize)]
pub struct Report {
    /// Scenario name.
    pub scenario: String,
    /// Target name.
    pub target: String,
    /// Seed list name.
    pub seed_set: String,
    /// Seeds run.
    pub seeds: Vec<u64>,
    /// Frames per run.
    pub frames: usize,
    /// The configuration note.
    pub configuration: String,
    /// Modes by name.
    pub modes: BTreeMap<String, Mode>,
}

/// Every report of `dir`, sorted by file name.
pub fn load(dir: &Path) -> Result<Vec<(String, Report)>> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|path| {
            let text = std::fs::read_to_string(&path)
                .with_context(|| format!("reading {}", path.display()))?;
            let report: Report = serde_json::from_str(&text)
                .with_context(|| format!("parsing {}", path.display()))?;
            let name = path
                .file_stem()
                .map_or_else(String::new, |s| s.to_string_lossy().into());
            Ok((name, report))
        })
        .collect()
}

fn cell(v: Option<f64>, decimals: usize) -> String {
    v.map_or_else(|| "-".to_string(), |v| crate::table::num(v, decimals))
}

/// The table: per report and mode, the whole-run angle (start-up
/// included) over the seeds, the mean angle with its interval, the
/// position, and the failures summed over the seeds.
pub fn table(reports: &[(String, Report)]) -> String {
    let mut out = String::from(
        "Whole runs from the truth with zero rates, or, where the configuration says \
         \"acquired by init\", from init's acquisitions with no truth (errors then with d_sym \
         over the target's symmetries); start-up included; one row per \
         report file and mode; \"max\" is each seed's largest error, then its mean / p95 / \
         max over the seeds. Acquisitions: correct / false accepts / rejected, summed over \
         the seeds (a false accept is an accepted pose more than 10° or 50 cm off). \
         Silent: frames published `tracking` more than 10° or 50 cm off; unconfirmed: \
         frames published `unconfirmed` (the acquisition awaiting its verification \
         by a second look), with those of them that far off. \
         Consistency: each run's median NEES of the published pose and of the filter's \
         posterior, and its median NIS, averaged over the seeds (χ²(6) median 5.3).\n\n",
    );
    out.push_str("| file | target | scenario | configuration | mode | seeds × frames | angle max: mean / p95 / max (°) | angle mean (95 % CI) (°) | position mean / p95 of max (cm) | lost | diverged | silent | unconfirmed (far off) | acquisitions | NEES published / filter, NIS |\n");
    out.push_str("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (file, r) in reports {
        for (mode, m) in &r.modes {
            let get = |k: &str| m.stats.get(k).copied();
            let max = get("ang_max_deg");
            let mean = get("ang_mean_deg");
            let sum = |f: fn(&Counts) -> usize| m.per_seed.iter().map(f).sum::<usize>();
            out.push_str(&format!(
                "| {file} | {} | {} | {} | {mode} | {} × {} ({}) | {} / {} / {} | {} ({}-{}) | {} / {} | {} | {} | {} | {} ({}) | {} | {} |\n",
                r.target,
                r.scenario,
                r.configuration,
                r.seeds.len(),
                r.frames,
                r.seed_set,
                cell(max.and_then(|s| s.mean), 2),
                cell(max.and_then(|s| s.p95), 2),
                cell(max.and_then(|s| s.max), 2),
                cell(mean.and_then(|s| s.mean), 2),
                cell(mean.and_then(|s| s.ci95[0]), 2),
                cell(mean.and_then(|s| s.ci95[1]), 2),
                cell(get("pos_mean_cm").and_then(|s| s.mean), 1),
                cell(get("pos_max_cm").and_then(|s| s.p95), 1),
                sum(|c| c.lost),
                sum(|c| c.diverged),
                sum(|c| c.silent),
                sum(|c| c.unconfirmed),
                sum(|c| c.unconfirmed_far_off),
                acquisitions(m),
                consistency(m),
            ));
        }
    }
    out
}

/// The mean over the seeds of each run's median NEES (published, filter)
/// and NIS; `-` for a figure the report does not have.
fn consistency(m: &Mode) -> String {
    let mean = |k: &str| cell(m.stats.get(k).and_then(|s| s.mean), 1);
    format!(
        "{} / {}, {}",
        mean("nees_median"),
        mean("filter_nees_median"),
        mean("nis_median")
    )
}

/// `correct / false accepts / rejected` over the seeds, `-` when the
/// runs started from the truth.
fn acquisitions(m: &Mode) -> String {
    let sum = |f: fn(&Acquisitions) -> usize| {
        m.per_seed.iter().map(|c| f(&c.acquisitions)).sum::<usize>()
    };
    let (c, f, r) = (
        sum(|a| a.correct),
        sum(|a| a.false_accepts),
        sum(|a| a.rejected),
    );
    if c + f + r == 0 {
        "-".to_string()
    } else {
        format!("{c} / {f} / {r}")
    }
}

/// The README's table: the suite's defaults (`*-defaults` reports), per
/// scenario and mode, the whole run's worst angle over the seeds, the mean
/// angle, the position, and the frames far off that went out as `tracking`.
pub fn headline(reports: &[(String, Report)]) -> String {
    let defaults: Vec<&(String, Report)> = reports
        .iter()
        .filter(|(f, _)| f.ends_with("-defaults"))
        .collect();
    let Some((_, first)) = defaults.first() else {
        return "No Monte-Carlo report yet (`docs/results/monte-carlo/measure.sh`).\n".into();
    };
    let mut out = format!(
        "{} blind seeds × {} frames per scenario, on {}, from the truth with zero rates; \
         the whole run, start-up included\n\n",
        first.seeds.len(),
        first.frames,
        first.target
    );
    out.push_str("| scenario | mode | angle max per run: p95 / max (°) | angle mean (°) | position max per run: p95 (cm) | frames > 10° or 50 cm off | of them published as tracking |\n");
    out.push_str("|---|---|---|---|---|---|---|\n");
    for (_, r) in defaults {
        for (mode, m) in &r.modes {
            let get = |k: &str| m.stats.get(k).copied();
            let sum = |f: fn(&Counts) -> usize| m.per_seed.iter().map(f).sum::<usize>();
            out.push_str(&format!(
                "| {} | {mode} | {} / {} | {} | {} | {} | {} |\n",
                r.scenario,
                cell(get("ang_max_deg").and_then(|s| s.p95), 2),
                cell(get("ang_max_deg").and_then(|s| s.max), 2),
                cell(get("ang_mean_deg").and_then(|s| s.mean), 2),
                cell(get("pos_max_cm").and_then(|s| s.p95), 1),
                sum(|c| c.diverged),
                sum(|c| c.silent),
            ));
        }
    }
    out
}
