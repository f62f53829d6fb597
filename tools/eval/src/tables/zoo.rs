//! The zoo's tracking table (issue 24): every committed `eval tracking`
//! run under [`ZOO_TRACKING_RUNS`] (one per design and scenario, `deblur`
//! and `ct-ndt`), one row per design, and how many designs meet the
//! issue's goal.

use super::runs::{FrameErr, Run};
use std::collections::BTreeMap;

/// Committed runs on the generated designs (`docs/results/measure-zoo-tracking.sh`).
pub const ZOO_TRACKING_RUNS: &str = "docs/results/zoo-tracking";

/// Issue 24's bound on the angle after the warm-up (deg).
const GOAL_DEG: f64 = 3.0;

/// Largest angle of the published frames from `from` on (NaN: none;
/// infinite when a frame from there on is lost: the run did not hold).
fn max_from(series: &[FrameErr], from: usize) -> f64 {
    let tail = series.iter().filter(|f| f.frame >= from);
    tail.fold(f64::NAN, |m, f| match (f.status.as_str(), f.ang_err_deg) {
        ("lost", _) | (_, None) => f64::INFINITY,
        (_, Some(a)) => m.max(a),
    })
}

fn silent(series: &[FrameErr]) -> usize {
    series
        .iter()
        .filter(|f| f.status == "tracking" && f.far_off())
        .count()
}

fn cell(v: f64) -> String {
    if v.is_infinite() {
        "lost".into()
    } else {
        crate::table::num(v, 2)
    }
}

/// The table and its summary.
pub fn table(runs: &[Run]) -> String {
    let mut by_design: BTreeMap<&str, BTreeMap<&str, &Run>> = BTreeMap::new();
    for r in runs {
        by_design
            .entry(&r.target)
            .or_default()
            .insert(&r.scenario, r);
    }
    let seed = runs.first().map_or(0, |r| r.seed);
    let mut out = format!(
        "Scenario seed {seed}, 120 frames from the truth with zero rates, every sensor effect \
         on. max* = largest angle after the 10 warm-up frames (\"lost\": a frame after them \
         was lost); whole = the whole run, start-up included; silent = frames published \
         `tracking` more than 10° or 50 cm off (both modes).\n\n"
    );
    out.push_str("| design | tumbling max* deblur / ct-ndt (°) | tumbling whole deblur / ct-ndt (°) | slow-spin max* deblur / ct-ndt (°) | silent |\n");
    out.push_str("|---|---|---|---|---|\n");
    let modes = ["deblur", "ct-ndt"];
    let (mut held, mut total_silent) = (0, 0);
    for (design, scenarios) in &by_design {
        let series = |sc: &str, m: &str| {
            scenarios
                .get(sc)
                .and_then(|r| r.modes.get(m).map(|x| (r.warmup, x.series.as_slice())))
        };
        let maxes = |sc: &str, from_warmup: bool| -> Vec<f64> {
            modes
                .iter()
                .map(|m| {
                    series(sc, m).map_or(f64::NAN, |(w, s)| {
                        max_from(s, if from_warmup { w } else { 0 })
                    })
                })
                .collect()
        };
        let (tw, tz, sw) = (
            maxes("tumbling", true),
            maxes("tumbling", false),
            maxes("slow-spin", true),
        );
        let s: usize = ["tumbling", "slow-spin"]
            .iter()
            .flat_map(|sc| modes.iter().filter_map(move |m| series(sc, m)))
            .map(|(_, x)| silent(x))
            .sum();
        total_silent += s;
        if tw.iter().chain(&sw).all(|m| *m <= GOAL_DEG) {
            held += 1;
        }
        out.push_str(&format!(
            "| {design} | {} / {} | {} / {} | {} / {} | {s} |\n",
            cell(tw[0]),
            cell(tw[1]),
            cell(tz[0]),
            cell(tz[1]),
            cell(sw[0]),
            cell(sw[1])
        ));
    }
    out.push_str(&format!(
        "\n{} designs. Held with max* <= {GOAL_DEG}° in both modes and both scenarios: {held}. \
         Silent frames: {total_silent}.\n",
        by_design.len()
    ));
    out
}
