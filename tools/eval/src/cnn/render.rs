//! Text of the `eval cnn` report: the summary line, Tables III and IV, the
//! f_CONV check, success by range and the per-frame table that
//! [`super::cnn::print`] prints.

use super::report::{CnnFrame, CnnReport, FconvStats, MeanStd, RangeBin, TimeSplit};
use crate::table::{Table, num, sci};

/// The first line: the run, the mean points, the estimator errors, the
/// hypotheses and the twin check.
pub fn summary_line(report: &CnnReport) -> String {
    format!(
        "CNN pose estimation, {} held-out frames (seed {}{}), target {}, model {}, engine {} (one thread); \
         mean {:.0} points per frame; {} estimator errors; {} frames refined several \
         hypotheses, {} reported a hypothesis other than Γ_sym's (max {}); twin check: \
         {} frames refined a twin, {} reported it",
        report.count,
        report.seed,
        if report.mismatch {
            "; outside the training: the target as built, 1.5x range noise, up to 10°/s"
        } else {
            ""
        },
        report.target,
        report.model,
        report.engine,
        report.mean_points,
        report.errors,
        report.several_hypotheses,
        report.other_hypothesis,
        report.config.hypotheses,
        report.twins_refined,
        report.twin_used
    )
}

/// A fraction as a percentage with one decimal, no unit ("-" when not
/// finite).
fn pct(v: f64) -> String {
    num(100.0 * v, 1)
}

/// "mean ± std" with `decimals` digits.
fn mean_std(m: MeanStd, decimals: usize) -> String {
    format!("{} ± {}", num(m.mean, decimals), num(m.std, decimals))
}

/// Table III: success and errors before and after refinement.
pub fn table3(report: &CnnReport) -> Table {
    let mut t3 = Table::new(&[
        "step",
        "success [%]",
        "position error [cm]",
        "angular error [deg]",
    ]);
    t3.row(vec![
        "before refinement".into(),
        pct(report.success_rate_raw),
        mean_std(report.pos_err_cm.raw, 1),
        mean_std(report.ang_err_deg.raw, 2),
    ]);
    t3.row(vec![
        "after refinement".into(),
        pct(report.success_rate_refined),
        mean_std(report.pos_err_cm.refined, 1),
        mean_std(report.ang_err_deg.refined, 2),
    ]);
    t3
}

/// Table IV: the time of each step.
pub fn table4(t: &TimeSplit) -> Table {
    let mut t4 = Table::new(&["step", "median [ms]", "mean ± std [ms]", "p95 [ms]"]);
    for (name, s) in [
        ("preprocessing", t.preprocess),
        ("CNN inference", t.inference),
        ("NDT refinement", t.refinement),
        ("total", t.total),
    ] {
        t4.row(vec![
            name.into(),
            num(s.median, 2),
            format!("{} ± {}", num(s.mean, 2), num(s.std, 2)),
            num(s.p95, 2),
        ]);
    }
    t4
}

/// The f_CONV acceptance check in one line.
pub fn fconv_line(f: &FconvStats) -> String {
    format!(
        "f_CONV check (f_MAX {} m²): accepted {}%, false accepts {}, false rejects {}; \
         successes max {} median {} m², failures min {} median {} m²",
        sci(f.f_max_m2),
        pct(f.accepted_rate),
        f.false_accepts,
        f.false_rejects,
        sci(f.success_max_m2),
        sci(f.success_median_m2),
        sci(f.failure_min_m2),
        sci(f.failure_median_m2)
    )
}

/// What init hands the tracker: accepted and correct, and false accepts
/// (a wrong pose accepted as a success), over every frame.
pub fn acceptance_line(report: &CnnReport) -> String {
    format!(
        "handed to the tracker: accepted and correct {}%, false accepts {}% ({} of {} frames)",
        pct(report.accepted_correct_rate),
        pct(report.false_accept_rate),
        report.fconv.false_accepts,
        report.count
    )
}

/// Success by range.
pub fn range_table(bins: &[RangeBin]) -> Table {
    let mut t = Table::new(&[
        "range [m]",
        "frames",
        "raw [%]",
        "refined [%]",
        "accepted and correct [%]",
        "false accepts [%]",
    ]);
    for b in bins {
        t.row(vec![
            format!("{}-{}", b.range_m[0], b.range_m[1]),
            b.frames.to_string(),
            pct(b.success_rate_raw),
            pct(b.success_rate_refined),
            pct(b.accepted_correct_rate),
            pct(b.false_accept_rate),
        ]);
    }
    t
}

/// The per-frame table.
pub fn frames_table(frames: &[CnnFrame]) -> Table {
    let mut all = Table::new(&[
        "frame", "range", "points", "raw deg", "raw cm", "deg", "cm", "f_conv", "expl", "twin",
        "ok", "ms",
    ]);
    for r in frames {
        all.row(frame_row(r));
    }
    all
}

/// One frame's cells, in the order of [`frames_table`]'s columns.
fn frame_row(r: &CnnFrame) -> Vec<String> {
    vec![
        r.frame.to_string(),
        num(r.range_m, 1),
        r.points.to_string(),
        num(r.raw_err_deg, 2),
        num(r.raw_err_cm, 1),
        num(r.err_deg, 2),
        num(r.err_cm, 1),
        format!("{:.1e}", r.f_conv_m2),
        num(r.twins.explained, 3),
        twin_cell(&r.twins),
        r.success_refined.to_string(),
        num(r.time_ms.total, 1),
    ]
}

/// The twin check of one frame: "I used", "N kept" or "-".
fn twin_cell(twins: &spacepose_cnn::TwinOutcome) -> String {
    match (twins.twin, twins.twins_refined) {
        (Some(i), _) => format!("{i} used"),
        (None, 0) => "-".to_owned(),
        (None, n) => format!("{n} kept"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without any failure (or success) the f_CONV figures print "-", as
    /// every other figure without a value does, never "NaN".
    #[test]
    fn the_fconv_line_prints_a_dash_for_missing_figures() {
        let f = FconvStats {
            f_max_m2: 4e-4,
            accepted_rate: 1.0,
            false_accepts: 0,
            false_rejects: 0,
            success_max_m2: 1.5e-4,
            success_median_m2: 1.0e-4,
            failure_min_m2: f64::NAN,
            failure_median_m2: f64::NAN,
        };
        let line = fconv_line(&f);
        assert!(!line.contains("NaN"), "{line}");
        assert!(line.contains("f_MAX 4.00e-4 m²"), "{line}");
        assert!(
            line.contains("successes max 1.50e-4 median 1.00e-4 m²"),
            "{line}"
        );
        assert!(line.contains("failures min - median - m²"), "{line}");
    }
}
