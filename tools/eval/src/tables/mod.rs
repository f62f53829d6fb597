//! `spacepose eval tables`: the results tables of the README and `docs/`,
//! generated from the committed `eval tracking` runs under `docs/results/`
//! rather than copied by hand. Each table sits between the markers
//! `<!-- results:NAME -->` and `<!-- /results:NAME -->` of its file; the
//! command rewrites what is between them, and `--check` fails when a
//! committed table differs from what the committed runs give (a unit test
//! runs the check).

pub mod monte_carlo;
pub mod runs;
pub mod zoo;

use anyhow::{Context, Result, bail};
use runs::{Pooled, Pools, load_dir, pool, pool_by};
use std::path::{Path, PathBuf};

/// Arguments of `spacepose eval tables`.
#[derive(Debug, clap::Args)]
pub struct TablesArgs {
    /// Repository root (the README and `docs/` are read and written there).
    #[arg(long, default_value = ".")]
    pub root: PathBuf,
    /// Only check that the committed tables are up to date.
    #[arg(long)]
    pub check: bool,
}

/// Committed runs of the current suite on the blind seeds.
pub const BLIND_RUNS: &str = "docs/results/tracking-blind";
/// The same runs by the CLI before the one-frame-path change.
pub const FRAME_PATH_BEFORE_RUNS: &str = "docs/results/frame-path-before";

/// Runs on the other targets (`docs/results/measure-targets.sh`).
pub const TARGET_RUNS: &str = "docs/results/targets";

/// `(file, block name)` of every generated table.
pub const BLOCKS: [(&str, &str); 6] = [
    ("docs/design/target-packages.md", "zoo-tracking"),
    ("docs/results.md", "monte-carlo"),
    ("README.md", "headline"),
    ("docs/results.md", "tracking-blind"),
    ("docs/design/frame-path.md", "frame-path"),
    ("docs/design/target-packages.md", "targets"),
];

/// Runs the command.
pub fn run(args: &TablesArgs) -> Result<()> {
    let stale = update(&args.root, !args.check)?;
    if args.check && !stale.is_empty() {
        bail!(
            "tables out of date in {} (run `spacepose eval tables`)",
            stale.join(", ")
        );
    }
    for f in &stale {
        println!("updated {f}");
    }
    Ok(())
}

/// Generates every block; writes the files whose blocks changed when
/// `write`. Returns the files that were (or would be) changed.
pub fn update(root: &Path, write: bool) -> Result<Vec<String>> {
    let blind = pool(&load_dir(&root.join(BLIND_RUNS))?);
    let before = pool(&load_dir(&root.join(FRAME_PATH_BEFORE_RUNS))?);
    let targets = pool_by(&load_dir(&root.join(TARGET_RUNS))?, |r| r.target.clone());
    let reports = monte_carlo::load(&root.join(monte_carlo::MONTE_CARLO_RUNS))?;
    let zoo_runs = load_dir(&root.join(zoo::ZOO_TRACKING_RUNS))?;
    let mut stale = Vec::new();
    for (file, name) in BLOCKS {
        let body = match name {
            "monte-carlo" => monte_carlo::table(&reports),
            "zoo-tracking" => zoo::table(&zoo_runs),
            "headline" => monte_carlo::headline(&reports),
            "tracking-blind" => full(&blind),
            "targets" => by_target(&targets),
            _ => comparison(&before, &blind),
        };
        let path = root.join(file);
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        let new = replace_block(&text, name, &body)
            .with_context(|| format!("{}: no marker <!-- results:{name} -->", path.display()))?;
        if new != text {
            stale.push(file.to_string());
            if write {
                std::fs::write(&path, new)
                    .with_context(|| format!("writing {}", path.display()))?;
            }
        }
    }
    Ok(stale)
}

/// `text` with the block `name` replaced by `body` (the end marker is
/// added after a lone start marker); `None` without a start marker.
pub fn replace_block(text: &str, name: &str, body: &str) -> Option<String> {
    let start = format!("<!-- results:{name} -->");
    let end = format!("<!-- /results:{name} -->");
    let s = text.find(&start)? + start.len();
    let rest = &text[s..];
    let e = rest.find(&end).map_or(s, |e| s + e + end.len());
    Some(format!("{}\n{}{}{}", &text[..s], body, end, &text[e..]))
}

fn fmt(v: f64, decimals: usize) -> String {
    crate::table::num(v, decimals)
}

fn seeds_line(pools: &Pools) -> String {
    let p = pools.values().flat_map(|m| m.values()).next();
    let (seeds, frames) = p.map_or((0, 0), |p| (p.seeds, p.frames));
    format!(
        "{seeds} seeds (2001-2005: blind when measured, development since; measured before \
         the start-up), {frames} frames per scenario and mode after the warm-up; errors \
         pooled over every frame\n\n"
    )
}

/// The cells every pooled row shares: angle and position p50 / p95 / max,
/// lost, diverged and silent frames.
fn stats_cells(p: &Pooled) -> String {
    format!(
        "{} / {} / {} | {} / {} / {} | {} | {} | {}",
        fmt(p.ang_deg[0], 2),
        fmt(p.ang_deg[1], 2),
        fmt(p.ang_deg[2], 2),
        fmt(p.pos_cm[0], 1),
        fmt(p.pos_cm[1], 1),
        fmt(p.pos_cm[2], 1),
        p.lost,
        p.diverged,
        p.silent
    )
}

/// docs/results.md's table: every statistic.
fn full(pools: &Pools) -> String {
    let mut out = seeds_line(pools);
    out.push_str("| scenario | mode | seeds | frames | angle p50 / p95 / max (°) | position p50 / p95 / max (cm) | lost | diverged | silent |\n");
    out.push_str("|---|---|---|---|---|---|---|---|---|\n");
    for (scenario, modes) in pools {
        for (mode, p) in modes {
            let cells = stats_cells(p);
            let (seeds, frames) = (p.seeds, p.frames);
            out.push_str(&format!(
                "| {scenario} | {mode} | {seeds} | {frames} | {cells} |\n"
            ));
        }
    }
    out
}

/// The target-packages note's table: every target (tumbling, blind seeds).
fn by_target(pools: &Pools) -> String {
    let p = pools.values().flat_map(|m| m.values()).next();
    let (seeds, frames) = p.map_or((0, 0), |p| (p.seeds, p.frames));
    let mut out = format!(
        "tumbling, {seeds} seeds (2001-2005: blind when measured, development since; \
         measured before the start-up), {frames} frames per target and mode after the \
         warm-up; errors pooled over every frame\n\n"
    );
    out.push_str("| target | mode | angle p50 / p95 / max (°) | position p50 / p95 / max (cm) | lost | diverged | silent |\n");
    out.push_str("|---|---|---|---|---|---|---|\n");
    for (target, modes) in pools {
        for (mode, p) in modes {
            out.push_str(&format!("| {target} | {mode} | {} |\n", stats_cells(p)));
        }
    }
    out
}

/// The frame-path note's table: before → after.
fn comparison(before: &Pools, after: &Pools) -> String {
    let mut out = seeds_line(after);
    out.push_str("| scenario | mode | angle p50 (°) | angle p95 (°) | angle max (°) | position p95 (cm) | position max (cm) | diverged frames |\n");
    out.push_str("|---|---|---|---|---|---|---|---|\n");
    let arrow = |b: f64, a: f64, d: usize| format!("{} → {}", fmt(b, d), fmt(a, d));
    for (scenario, modes) in after {
        for (mode, a) in modes {
            let Some(b) = before.get(scenario).and_then(|m| m.get(mode)) else {
                continue;
            };
            let b: &Pooled = b;
            out.push_str(&format!(
                "| {scenario} | {mode} | {} | {} | {} | {} | {} | {} → {} |\n",
                arrow(b.ang_deg[0], a.ang_deg[0], 2),
                arrow(b.ang_deg[1], a.ang_deg[1], 2),
                arrow(b.ang_deg[2], a.ang_deg[2], 2),
                arrow(b.pos_cm[1], a.pos_cm[1], 1),
                arrow(b.pos_cm[2], a.pos_cm[2], 1),
                b.diverged,
                a.diverged
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_block_is_replaced_between_its_markers_or_after_a_lone_start() {
        let text = "a\n<!-- results:x -->\nold\n<!-- /results:x -->\nb\n";
        let new = replace_block(text, "x", "new\n").unwrap();
        assert_eq!(new, "a\n<!-- results:x -->\nnew\n<!-- /results:x -->\nb\n");
        assert_eq!(replace_block(&new, "x", "new\n").unwrap(), new);
        let lone = replace_block("<!-- results:x -->\nb\n", "x", "t\n").unwrap();
        assert_eq!(lone, "<!-- results:x -->\nt\n<!-- /results:x -->\nb\n");
        assert!(replace_block("nothing", "x", "t").is_none());
    }

    #[test]
    fn the_committed_tables_are_generated_from_the_committed_runs() {
        let root = Path::new(
            &std::env::var("CARGO_MANIFEST_DIR")
                .unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").to_owned()),
        )
        .join("../..");
        let stale = update(&root, false).unwrap();
        assert!(stale.is_empty(), "run `spacepose eval tables`: {stale:?}");
    }
}
