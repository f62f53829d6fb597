//! Text of the `eval tm` report: the header line, the summary table and the
//! per-frame table that [`super::tm::render`] puts together.

use super::args::SensorEffects;
use super::report::{TmFrame, TmReport};
use crate::table::{Table, num, sci};
use spacepose_acquisition::{TemplateMatchingConfig, Threads};
use std::fmt::Display;

/// The first line: target, scenario, seed, sensor effects, frames and the
/// matching settings, newline included.
pub fn header(report: &TmReport) -> String {
    let c = &report.config;
    format!(
        "template matching: {} / {}{} / seed {}{} / {} frames / Δ {}° {}/ {} / {}{} refined, mean {:.0} points\n",
        report.target,
        report.scenario,
        range_suffix(report.range_m),
        report.seed,
        sensor_suffix(report.sensor, report.sensor_effects),
        report.count,
        c.delta_deg,
        fast_label(c),
        threads_label(c),
        screening_label(c),
        c.icp_candidates,
        report.mean_points,
    )
}

/// The sensor (when not seed 002's raster) and its effects.
fn sensor_suffix(sensor: super::TmSensor, effects: SensorEffects) -> String {
    let name = match sensor {
        super::TmSensor::Raster => "",
        super::TmSensor::Mid40 => " / Mid-40, 2 cm voxels",
    };
    format!("{name}{}", effects_suffix(effects))
}

/// " at R m" for a fixed-range scenario (finite range), empty otherwise.
fn range_suffix(range_m: f64) -> String {
    if range_m.is_finite() {
        format!(" at {} m", range_m)
    } else {
        String::new()
    }
}

/// " / seed 002 sensor effects" when the frames carry only those.
fn effects_suffix(effects: SensorEffects) -> &'static str {
    match effects {
        SensorEffects::All => "",
        SensorEffects::Seed002 => " / seed 002 sensor effects",
    }
}

/// "fast τ T " for the fast variant (D_BOR test), empty otherwise.
fn fast_label(c: &TemplateMatchingConfig) -> String {
    if c.fast {
        format!("fast τ {} ", c.tau)
    } else {
        String::new()
    }
}

/// "1 thread" or "all threads".
fn threads_label(c: &TemplateMatchingConfig) -> &'static str {
    if c.threads == Threads::Single {
        "1 thread"
    } else {
        "all threads"
    }
}

/// "≤ N screened (budget B points…), " when the screening keeps more
/// candidates than ICP refines, empty otherwise.
fn screening_label(c: &TemplateMatchingConfig) -> String {
    if c.screen_candidates > c.icp_candidates {
        format!(
            "≤ {} screened (budget {} points{}), ",
            c.screen_candidates,
            c.screen_point_budget,
            rerank_label(c)
        )
    } else {
        String::new()
    }
}

/// ", best K re-ranked by U" when screened poses are re-ranked.
fn rerank_label(c: &TemplateMatchingConfig) -> String {
    if c.screen_rerank > 0 {
        format!(", best {} re-ranked by U", c.screen_rerank)
    } else {
        String::new()
    }
}

/// The summary table (figure, value).
pub fn summary_table(report: &TmReport) -> Table {
    let mut t = Table::new(&["figure", "value"]);
    outcome_rows(&mut t, report);
    accuracy_rows(&mut t, report);
    cost_rows(&mut t, report);
    fconv_rows(&mut t, report);
    t
}

/// A fraction as a percentage with one decimal ("66.7 %").
fn percent(v: f64) -> String {
    format!("{:.1} %", 100.0 * v)
}

/// Two values as "a / b".
fn pair(a: impl Display, b: impl Display) -> String {
    format!("{} / {}", a, b)
}

/// Appends a (figure, value) row.
fn add(t: &mut Table, figure: impl Into<String>, value: String) {
    t.row(vec![figure.into(), value]);
}

/// Rows of success, acceptance and their disagreements.
fn outcome_rows(t: &mut Table, report: &TmReport) {
    let c = &report.config;
    add(
        t,
        "success rate after ICP (< 3°)",
        percent(report.success_rate),
    );
    add(
        t,
        format!("accepted (f_CONV ≤ {} m², U ≤ {})", c.f_max_m2, c.u_max),
        percent(report.accepted_rate),
    );
    add(
        t,
        "accepted and successful",
        percent(report.accepted_success_rate),
    );
    add(
        t,
        "false accepts / false rejects",
        pair(report.false_accepts, report.false_rejects),
    );
}

/// Rows of the attitude errors over the successes.
fn accuracy_rows(t: &mut Table, report: &TmReport) {
    let e = report.euler_err_deg;
    add(
        t,
        "TM Euler error yaw/pitch/roll (deg, successes)",
        format!("{} / {} / {}", num(e[0], 1), num(e[1], 1), num(e[2], 1)),
    );
    add(
        t,
        "attitude error after ICP (deg, successes)",
        num(report.err_deg_success_mean, 2),
    );
}

/// Rows of the template counts and the acquisition times.
fn cost_rows(t: &mut Table, report: &TmReport) {
    let n = &report.templates;
    add(
        t,
        "templates generated / evaluated (grid)",
        format!("{:.0} / {:.0} ({})", n.generated, n.evaluated, n.grid),
    );
    add(
        t,
        "time per acquisition mean / max (ms)",
        pair(num(report.time_ms.mean, 1), num(report.time_ms.max, 1)),
    );
    add(
        t,
        "  of which matching / ICP mean (ms)",
        pair(
            num(report.matching_ms.mean, 1),
            num(report.refinement_ms.mean, 1),
        ),
    );
}

/// Rows of f_CONV and the unexplained fraction over successes and failures
/// (seed 002 Table 4).
fn fconv_rows(t: &mut Table, report: &TmReport) {
    add(
        t,
        "f_CONV success max / mean (m²)",
        pair(
            sci(report.fconv_success_max),
            sci(report.fconv_success_mean),
        ),
    );
    add(
        t,
        "f_CONV failure min / mean (m²)",
        pair(
            sci(report.fconv_failure_min),
            sci(report.fconv_failure_mean),
        ),
    );
    add(
        t,
        "f_CONV separates success from failure",
        report.separable.to_string(),
    );
    add(
        t,
        "unexplained U success max / failure min (f_CONV ok)",
        pair(
            num(report.unexplained_success_max, 3),
            num(report.unexplained_failure_min, 3),
        ),
    );
}

/// The per-frame table.
pub fn frames_table(frames: &[TmFrame]) -> Table {
    let mut f = Table::new(&[
        "frame",
        "range m",
        "points",
        "err deg",
        "TM err deg",
        "f_CONV m²",
        "ms",
        "note",
    ]);
    for r in frames {
        f.row(frame_row(r));
    }
    f
}

/// One frame's cells, in the order of [`frames_table`]'s columns.
fn frame_row(r: &TmFrame) -> Vec<String> {
    vec![
        r.frame.to_string(),
        num(r.range_m, 1),
        r.points.to_string(),
        num(r.err_deg, 2),
        num(r.coarse_err_deg, 1),
        sci(r.f_conv_m2),
        num(r.time_ms, 0),
        r.error.clone().unwrap_or_default(),
    ]
}
