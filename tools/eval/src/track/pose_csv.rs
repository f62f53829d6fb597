//! The poses of `spacepose track`, one CSV row per frame.
//!
//! Only what the pipeline decides is written (no timings), with Rust's
//! shortest round-trip formatting: the same recording gives the same
//! bytes, so two runs compare with `cmp`.

use anyhow::{Context, Result};
use spacepose_messages::{PoseEstimate, WireStatus};
use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;

/// The header line (without newline).
pub const HEADER: &str = "frame,sequence,scan_start_s,scan_end_s,status,px_m,py_m,pz_m,qw,qx,qy,qz,iterations,cost,inliers,points_used,acquired";

/// The pose of one frame, as published.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseRow {
    /// Frame index of the recording.
    pub frame: u64,
    /// Scan interval (s, sensor clock).
    pub scan_start_s: f64,
    /// See `scan_start_s`.
    pub scan_end_s: f64,
    /// The estimate the tracker published.
    pub estimate: PoseEstimate,
    /// The method of an acquisition init accepted on this frame (it applies
    /// from the next frame), empty otherwise.
    pub acquired: &'static str,
}

/// `tracking`, `degraded`, `lost` or `unconfirmed` (an unknown code reads
/// `lost`).
pub fn status_name(estimate: &PoseEstimate) -> &'static str {
    estimate.wire_status().map_or("lost", WireStatus::as_str)
}

impl PoseRow {
    /// The CSV line (without newline).
    pub fn line(&self) -> String {
        let e = &self.estimate;
        let mut s = format!(
            "{},{},{},{},{}",
            self.frame,
            e.sequence,
            self.scan_start_s,
            self.scan_end_s,
            status_name(e)
        );
        for x in e.p_sensor_target.iter().chain(&e.q_sensor_target) {
            let _ = write!(s, ",{x}");
        }
        let _ = write!(
            s,
            ",{},{},{},{},{}",
            e.iterations, e.cost, e.inliers, e.points_used, self.acquired
        );
        s
    }
}

/// Writes `rows` to `path` (CSV with [`HEADER`]).
pub fn write(path: &Path, rows: &[PoseRow]) -> Result<()> {
    let mut text = String::with_capacity(64 + rows.len() * 160);
    text.push_str(HEADER);
    text.push('\n');
    for r in rows {
        text.push_str(&r.line());
        text.push('\n');
    }
    let mut file =
        std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
    file.write_all(text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_row_has_every_column_of_the_header() {
        let mut estimate = PoseEstimate::new();
        estimate.sequence = 4;
        estimate.p_sensor_target = [0.1, -0.2, 15.0];
        let row = PoseRow {
            frame: 4,
            scan_start_s: 3.0,
            scan_end_s: 4.0,
            estimate,
            acquired: "cnn",
        };
        let line = row.line();
        assert_eq!(line.split(',').count(), HEADER.split(',').count());
        assert!(line.starts_with("4,4,3,4,"), "{line}");
        assert!(line.contains(",0.1,-0.2,15,1,0,0,0,"), "{line}");
        assert!(line.ends_with(",cnn"), "{line}");
    }
}
