//! Text output of the demo: one live line per frame and the final table
//! (layout of seed 000 Table 3: errors and execution time, mean and max).

use super::score::{FrameScore, Summary};
use spacepose_eval::table::{Table, num};
use std::time::Duration;

/// Header of the live lines.
pub fn live_header() -> String {
    format!(
        "{:>7}  {:>5}  {:<9}  {:>11}  {:>10}  {:>10}  {:>10}  {:>11}",
        "t s",
        "frame",
        "status",
        "ang err deg",
        "pos err cm",
        "tracker ms",
        "latency ms",
        "overhead ms"
    )
}

/// One frame, as it arrives.
pub fn live_line(f: &FrameScore, since_start: Duration) -> String {
    format!(
        "{:>7.2}  {:>5}  {:<9}  {:>11}  {:>10}  {:>10}  {:>10}  {:>11}",
        since_start.as_secs_f64(),
        f.sequence,
        f.status,
        num(f.ang_err_deg, 2),
        num(f.pos_err_cm, 2),
        num(f.tracker_ms, 2),
        num(f.latency_ms, 2),
        num(f.overhead_ms, 3),
    )
}

/// The final table and the counts below it.
pub fn final_table(s: &Summary) -> String {
    let mut t = Table::new(&[
        "mode", "ang mean", "ang max", "ang max*", "pos mean", "pos max", "ms mean", "ms max",
        "it mean", "it max",
    ]);
    t.row(vec![
        s.mode.clone(),
        num(s.ang_err_deg.mean, 2),
        num(s.ang_err_deg.max, 2),
        num(s.ang_err_deg_converged.max, 2),
        num(s.pos_err_cm.mean, 2),
        num(s.pos_err_cm.max, 2),
        num(s.tracker_ms.mean, 2),
        num(s.tracker_ms.max, 2),
        num(s.iterations.mean, 1),
        num(s.iterations.max, 0),
    ]);
    let statuses: Vec<String> = s
        .status_counts
        .iter()
        .map(|(k, v)| format!("{k} {v}"))
        .collect();
    format!(
        "\nerrors in deg and cm, tracker time in ms per frame (its own process, one thread);\n\
         ang max* = max after {} warm-up frames\n{}\
         frames {}  published {}  poses {}  missed {}  ({})\n\
         latency sensor->pose ms: mean {}  median {}  max {}\n\
         pipeline overhead (latency - tracker) ms: mean {}  median {}  max {}\n",
        s.warmup,
        t.render(),
        s.frames,
        s.frames_published,
        s.poses_published,
        s.missed_poses,
        statuses.join(", "),
        num(s.latency_ms.mean, 2),
        num(s.latency_ms.median, 2),
        num(s.latency_ms.max, 2),
        num(s.overhead_ms.mean, 3),
        num(s.overhead_ms.median, 3),
        num(s.overhead_ms.max, 3),
    )
}

/// The chaos and swap results, one line each (empty without them).
pub fn chaos_lines(s: &Summary) -> String {
    let opt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.1}"));
    let mut text = String::new();
    for c in &s.chaos {
        text.push_str(&format!(
            "chaos {:?} {} @{}: detected by {} after {} ms; restarted (first heartbeat) {} ms after detection; next frame {} ({} ms after), takeover {} ms\n",
            c.action,
            c.instance,
            c.at_frame,
            if c.detected_by.is_empty() { "-" } else { &c.detected_by },
            opt(c.detection_ms),
            opt(c.restart_ms),
            c.first_frame_after.map_or("-".to_string(), |k| k.to_string()),
            opt(c.first_frame_after_ms),
            opt(c.takeover_ms),
        ));
    }
    if let Some(w) = &s.swap {
        text.push_str(&w.line());
        text.push('\n');
    }
    if !s.chaos.is_empty() || s.swap.is_some() {
        text.push_str(&format!(
            "missed poses {}  tracked frames not fused {}  fusion latency ms: median {}  max {}\n",
            s.missed_poses,
            s.unfused_tracking_frames,
            num(s.fusion_latency_ms.median, 1),
            num(s.fusion_latency_ms.max, 1)
        ));
    }
    text
}
