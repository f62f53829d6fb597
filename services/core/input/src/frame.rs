//! One recorded frame, with where its times came from.

use spacepose_geometry::{Point, PointTimes};

/// Where a frame's scan interval came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScanTimeSource {
    /// The frame's row of `truth.csv` (PCD/PLY directory).
    TruthCsv,
    /// The JSON `<topic>/header` message spacepose logs beside its clouds.
    SpaceposeHeader,
    /// The smallest and largest finite point time.
    PointTimes,
    /// No time anywhere: the reference time (header stamp, or frame index
    /// times the scan period) plus the configured scan period.
    ScanPeriod,
}

/// One frame of a recording.
#[derive(Debug, Clone, PartialEq)]
pub struct InputFrame {
    /// Frame index: from the file name (`frame_000042.pcd` → 42), the
    /// spacepose header sequence, or the message's rank on its topic.
    pub index: u64,
    /// Where it came from, for logs (a path, or a topic and log time).
    pub origin: String,
    /// Coordinate frame name of the message (empty for PCD/PLY files).
    pub frame_id: String,
    /// Points in the sensor frame, `t` absolute on the sensor clock (s).
    /// Non-finite points are kept, except those dropped from a PointCloud2
    /// with `is_dense = false` (counted in [`InputFrame::dropped_non_finite`]).
    pub points: Vec<Point>,
    /// Scan start (s, sensor clock).
    pub scan_start_s: f64,
    /// Scan end (s, sensor clock).
    pub scan_end_s: f64,
    /// Where the scan interval came from.
    pub scan_time_source: ScanTimeSource,
    /// Where the per-point times came from: a field, or derived (warn and count).
    pub point_times: PointTimes,
    /// Non-finite points dropped (PointCloud2 with `is_dense = false`).
    pub dropped_non_finite: usize,
}

impl InputFrame {
    /// True when the per-point times were derived from the scan interval
    /// and the point order (no time field): the caller should warn and count.
    pub fn times_derived(&self) -> bool {
        self.point_times == PointTimes::Derived
    }

    /// Shifts the scan interval and every point time by `dt_s` (for
    /// looping: each pass continues the clock of the previous one).
    pub fn shift_time(&mut self, dt_s: f64) {
        self.scan_start_s += dt_s;
        self.scan_end_s += dt_s;
        for p in &mut self.points {
            p.t += dt_s;
        }
    }
}

/// Smallest and largest finite point time.
pub(crate) fn time_span(points: &[Point]) -> Option<(f64, f64)> {
    let mut it = points.iter().map(|p| p.t).filter(|t| t.is_finite());
    let first = it.next()?;
    Some(it.fold((first, first), |(lo, hi), t| (lo.min(t), hi.max(t))))
}
