//! Printing `spacepose eval tracking`: the table of seed 000 Tables 2-3
//! with the paper's rows, a preamble on the run, and notes on frames that
//! were not ordinary registrations.

use super::report::{DIVERGED_DEG, DIVERGED_M, ModeReport, TrackingReport};
use crate::table::{Table, num};

/// The columns, as in seed 000 Tables 2-3 (`ang max*`: after warm-up).
const COLUMNS: [&str; 13] = [
    "mode",
    "ang mean",
    "ang max",
    "ang max*",
    "pos mean",
    "pos max",
    "ms mean",
    "ms median",
    "ms max",
    "it mean",
    "it max",
    "lost",
    "diverged",
];

/// The paper's figures for the same scenario (seed 000 Tables 2-3):
/// (mode, ang mean, ang max, pos mean, pos max, time mean, time max, it mean, it max).
fn paper_rows(scenario: &str) -> &'static [(&'static str, [f64; 8])] {
    match scenario {
        "slow-spin" => &[
            ("ndt", [1.39, 2.59, 4.10, 10.21, 35.4, 94.0, 9.9, 20.0]),
            ("deblur", [1.00, 2.00, 4.00, 9.86, 22.2, 62.0, 4.3, 20.0]),
            ("ct-ndt", [1.01, 2.09, 4.01, 8.32, 41.8, 127.0, 6.9, 20.0]),
            ("icp", [1.91, 4.65, 4.85, 9.94, 174.4, 432.0, 32.7, 40.0]),
        ],
        "tumbling" => &[
            ("deblur", [1.27, 8.26, 3.26, 6.25, 26.4, 81.0, 5.4, 20.0]),
            ("ct-ndt", [1.37, 3.11, 3.56, 7.36, 47.0, 137.0, 7.1, 20.0]),
        ],
        _ => &[],
    }
}

/// One mode's row.
fn mode_row(name: &str, m: &ModeReport) -> Vec<String> {
    vec![
        name.to_string(),
        num(m.ang_err_deg.mean, 2),
        num(m.ang_err_deg.max, 2),
        num(m.ang_err_deg_converged.max, 2),
        num(m.pos_err_cm.mean, 2),
        num(m.pos_err_cm.max, 2),
        num(m.time_ms.mean, 2),
        num(m.time_ms_median, 2),
        num(m.time_ms.max, 2),
        num(m.iterations.mean, 1),
        num(m.iterations.max, 0),
        m.lost_frames.to_string(),
        m.diverged_frames.to_string(),
    ]
}

/// The paper's row for `name` (no median, no post-warm-up max, no
/// divergence count; it lost no frame in the runs it reports).
fn paper_row(name: &str, v: &[f64; 8]) -> Vec<String> {
    vec![
        format!("paper {name}"),
        num(v[0], 2),
        num(v[1], 2),
        "-".into(),
        num(v[2], 2),
        num(v[3], 2),
        num(v[4], 1),
        "-".into(),
        num(v[5], 0),
        num(v[6], 1),
        num(v[7], 0),
        "0".into(),
        "-".into(),
    ]
}

/// The run, the units and the scan blur, above the table.
fn preamble(report: &TrackingReport) -> String {
    format!(
        "{} with {}{}: {} frames from frame {} (seed {}, compression {}), {:.0} raw points per frame on average\n\
         errors in deg and cm; time in ms per frame, one thread, voxel filter included;\n\
         ang max* = max after {} warm-up frames; diverged = true error > {DIVERGED_DEG}° or {} cm\n\
         scan blur: the truth turns {:.2}° on average ({:.2}° max) between a frame's mean return time and its end\n",
        report.scenario,
        report.target,
        match (report.clutter, report.mismatch) {
            (false, false) => "",
            (true, false) => ", facility clutter on",
            (false, true) => ", model mismatch",
            (true, true) => ", facility clutter on, model mismatch",
        },
        report.frames,
        report.first_frame,
        report.seed,
        report.compression,
        report.mean_points_in,
        report.warmup,
        DIVERGED_M * 100.0,
        report.blur_lag_deg.mean,
        report.blur_lag_deg.max,
    )
}

/// One line per mode with stall fallbacks or degraded frames, below the
/// table.
fn notes(report: &TrackingReport) -> String {
    let mut s = String::new();
    for (name, m) in &report.modes {
        let a = m.acquisitions;
        if a != Default::default() {
            s += &format!(
                "{name}: acquisitions: {} correct, {} false accepts, {} rejected; {} frames published tracking while far off\n",
                a.correct, a.false_accepts, a.rejected, m.silent_frames
            );
        }
        if m.nees.frames > 0 {
            s += &format!(
                "{name}: NEES of the published covariance over {} frames: mean {:.1}, median {:.1} (χ²(6): 6, 5.3); above the χ² 95 % bound in {:.0} % of frames (5 % if consistent), 99.9 % bound in {:.0} %\n",
                m.nees.frames,
                m.nees.mean,
                m.nees.median,
                100.0 * m.nees.above_95,
                100.0 * m.nees.above_999
            );
        }
        if m.filter_nees.frames > 0 {
            s += &format!(
                "{name}: the filter's posterior over the {} frames it fused: error mean {:.2} / max {:.2} deg, {:.1} / {:.1} cm; NEES median {:.1}, above the 95 % bound in {:.0} %\n",
                m.filter_nees.frames,
                m.filter_ang_err_deg.mean,
                m.filter_ang_err_deg.max,
                m.filter_pos_err_cm.mean,
                m.filter_pos_err_cm.max,
                m.filter_nees.median,
                100.0 * m.filter_nees.above_95
            );
        }
        if m.nis.frames > 0 {
            s += &format!(
                "{name}: NIS of the registrations against the prediction over {} frames: median {:.1}, above the 95 % bound in {:.0} %\n",
                m.nis.frames,
                m.nis.median,
                100.0 * m.nis.above_95
            );
        }
        if m.fallback_frames > 0 {
            s += &format!(
                "{name}: {} frames fitted as deblur after CT-NDT stalled\n",
                m.fallback_frames
            );
        }
        if m.unconfirmed_frames > 0 {
            s += &format!(
                "{name}: {} frames unconfirmed (the acquisition not yet confirmed by a second look)\n",
                m.unconfirmed_frames
            );
        }
        if m.degraded_frames > 0 {
            let published = if published_prediction(name) {
                "the filter's prediction was published"
            } else {
                "the doubted registration was published"
            };
            s += &format!(
                "{name}: {} degraded frames, not fused; {published}\n",
                m.degraded_frames
            );
        }
    }
    s
}

/// True for the modes that publish the filter's prediction for a degraded
/// frame (`spacepose_tracker::TrackingMode::uses_prediction`).
fn published_prediction(mode: &str) -> bool {
    mode.parse::<spacepose_tracker::TrackingMode>()
        .is_ok_and(|m| m.uses_prediction())
}

/// The report as the table of seed 000 Tables 2-3, with the paper's rows.
pub fn render(report: &TrackingReport) -> String {
    let mut t = Table::new(&COLUMNS);
    for (name, m) in &report.modes {
        t.row(mode_row(name, m));
    }
    for (name, v) in paper_rows(&report.scenario) {
        t.row(paper_row(name, v));
    }
    preamble(report) + &t.render() + &notes(report)
}

/// The `--report` Monte-Carlo as one row per mode: the whole-run angle
/// (start-up included) and position figures over the seeds, and the
/// failures summed.
pub fn render_monte_carlo(r: &super::monte_carlo::MonteCarloReport) -> String {
    let mut t = Table::new(&[
        "mode",
        "ang max mean / p95 / max",
        "ang mean (95% CI)",
        "ang max* p95",
        "pos mean (cm)",
        "pos max p95 (cm)",
        "lost",
        "diverged",
        "silent",
        "acquired / false acc. / rejected",
    ]);
    for (name, m) in &r.modes {
        let st = |k: &str| m.stats.get(k).copied();
        let f = |k: &str, d: usize, g: fn(&super::monte_carlo::Spread) -> f64| {
            st(k).map_or_else(|| "-".to_string(), |s| num(g(&s), d))
        };
        let sum = |g: fn(&super::monte_carlo::SeedFigures) -> usize| {
            m.per_seed.iter().map(g).sum::<usize>().to_string()
        };
        let ci = st("ang_mean_deg").map_or_else(String::new, |s| {
            format!(" ({}-{})", num(s.ci95[0], 2), num(s.ci95[1], 2))
        });
        t.row(vec![
            name.clone(),
            format!(
                "{} / {} / {}",
                f("ang_max_deg", 2, |s| s.mean),
                f("ang_max_deg", 2, |s| s.p95),
                f("ang_max_deg", 2, |s| s.max)
            ),
            format!("{}{ci}", f("ang_mean_deg", 2, |s| s.mean)),
            f("ang_max_after_warmup_deg", 2, |s| s.p95),
            f("pos_mean_cm", 2, |s| s.mean),
            f("pos_max_cm", 1, |s| s.p95),
            sum(|s| s.lost),
            sum(|s| s.diverged),
            sum(|s| s.silent),
            format!(
                "{} / {} / {}",
                sum(|s| s.acquisitions.correct),
                sum(|s| s.acquisitions.false_accepts),
                sum(|s| s.acquisitions.rejected)
            ),
        ]);
    }
    let acquired = r
        .modes
        .values()
        .flat_map(|m| &m.per_seed)
        .any(|s| s.acquisitions != Default::default());
    let start = if acquired {
        "from init's acquisitions, no truth"
    } else {
        "from the truth with zero rates"
    };
    format!(
        "{} on {}: {} seeds ({}), {} frames each, whole runs {start} \
         (start-up included; max* = after {} warm-up frames); errors in deg and cm\n",
        r.scenario,
        r.target,
        r.seeds.len(),
        r.seed_set,
        r.frames,
        r.warmup
    ) + &t.render()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::MeanMax;
    use std::collections::BTreeMap;

    fn mm(mean: f64, max: f64) -> MeanMax {
        MeanMax { mean, max }
    }

    fn mode(degraded_frames: usize, fallback_frames: usize) -> ModeReport {
        ModeReport {
            ang_err_deg: mm(0.26, 1.47),
            pos_err_cm: mm(1.27, 18.59),
            time_ms: mm(4.2, 30.0),
            time_ms_median: 3.8,
            iterations: mm(6.4, 20.0),
            ang_err_deg_converged: mm(0.25, 1.4),
            pos_err_cm_converged: mm(1.2, 18.0),
            lost_frames: 0,
            degraded_frames,
            unconfirmed_frames: 0,
            diverged_frames: 0,
            fallback_frames,
            acquisitions: Default::default(),
            silent_frames: 0,
            nees: Default::default(),
            filter_ang_err_deg: mm(0.2, 1.2),
            filter_pos_err_cm: mm(1.1, 9.0),
            filter_nees: Default::default(),
            nis: Default::default(),
            frames: 100,
            series: Vec::new(),
        }
    }

    fn report(modes: BTreeMap<String, ModeReport>) -> TrackingReport {
        TrackingReport {
            scenario: "slow-spin".into(),
            target: "deos".into(),
            clutter: false,
            mismatch: false,
            seed: 7,
            frames: 100,
            first_frame: 0,
            compression: 1.0,
            warmup: 10,
            mean_points_in: 24000.0,
            blur_lag_deg: mm(0.55, 1.51),
            modes,
        }
    }

    #[test]
    fn the_table_has_every_mode_and_the_papers_rows() {
        let modes = BTreeMap::from([("deblur".to_string(), mode(0, 0))]);
        let out = render(&report(modes));
        let deblur = out.lines().find(|l| l.starts_with("deblur")).unwrap();
        assert!(deblur.contains("0.26") && deblur.contains("1.47"), "{out}");
        for name in ["paper ndt", "paper deblur", "paper ct-ndt", "paper icp"] {
            assert!(out.contains(name), "{name}: {out}");
        }
        assert!(out.starts_with("slow-spin with deos: 100 frames"), "{out}");
        assert!(out.contains("0.55° on average (1.51° max)"), "{out}");
        assert!(
            !out.contains("degraded") && !out.contains("stalled"),
            "{out}"
        );
    }

    #[test]
    fn degraded_frames_and_fallbacks_are_noted_with_what_was_published() {
        let modes = BTreeMap::from([
            ("ct-ndt".to_string(), mode(1, 2)),
            ("ndt".to_string(), mode(3, 0)),
        ]);
        let out = render(&report(modes));
        assert!(
            out.contains("ct-ndt: 2 frames fitted as deblur after CT-NDT stalled"),
            "{out}"
        );
        assert!(
            out.contains("ct-ndt: 1 degraded frames, not fused; the filter's prediction"),
            "{out}"
        );
        assert!(
            out.contains("ndt: 3 degraded frames, not fused; the doubted registration"),
            "{out}"
        );
    }
}
