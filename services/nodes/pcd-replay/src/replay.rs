//! A directory of recorded frames, read in frame order.

use crate::error::ReplayError;
use crate::truth::{ScanTimes, TruthTimes};
use spacepose_geometry::{Point, read_cloud};
use std::path::{Path, PathBuf};

/// Where a frame's scan interval came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeSource {
    /// The frame's row of `truth.csv`.
    TruthCsv,
    /// The smallest and largest finite point timestamps.
    PointTimestamps,
}

/// One frame read from disk.
#[derive(Debug, Clone, PartialEq)]
pub struct ReplayFrame {
    /// Frame index from the file name (`frame_000042.pcd` → 42).
    pub index: u64,
    /// The file.
    pub path: PathBuf,
    /// Points as stored (non-finite points are kept: the consumer rejects them).
    pub points: Vec<Point>,
    /// Scan start (s, sensor clock).
    pub scan_start_s: f64,
    /// Scan end (s, sensor clock).
    pub scan_end_s: f64,
    /// Where the scan times came from.
    pub time_source: TimeSource,
}

impl ReplayFrame {
    /// Shifts the scan interval and every point timestamp by `dt_s` (for
    /// looping: each pass continues the clock of the previous one).
    pub fn shift_time(&mut self, dt_s: f64) {
        self.scan_start_s += dt_s;
        self.scan_end_s += dt_s;
        for p in &mut self.points {
            p.t += dt_s;
        }
    }
}

/// The frames of a directory (`frame_NNNNNN.pcd` / `.ply`, as written by
/// `spacepose sim`), sorted by index, with `truth.csv` scan times when present.
#[derive(Debug)]
pub struct ReplayDir {
    dir: PathBuf,
    files: Vec<(u64, PathBuf)>,
    truth: TruthTimes,
    warnings: Vec<ReplayError>,
}

impl ReplayDir {
    /// Lists `dir` and reads its `truth.csv` if there is one. A corrupt
    /// truth file is reported in [`ReplayDir::warnings`], not fatal.
    ///
    /// # Errors
    /// [`ReplayError::Dir`] if `dir` cannot be listed, [`ReplayError::NoFrames`]
    /// if it holds no frame file.
    pub fn open(dir: impl AsRef<Path>) -> Result<ReplayDir, ReplayError> {
        let dir = dir.as_ref().to_owned();
        let io = |source| ReplayError::Dir {
            path: dir.clone(),
            source,
        };
        let mut files = Vec::new();
        for entry in std::fs::read_dir(&dir).map_err(io)? {
            let path = entry.map_err(io)?.path();
            if let Some(index) = frame_index(&path) {
                files.push((index, path));
            }
        }
        if files.is_empty() {
            return Err(ReplayError::NoFrames(dir));
        }
        files.sort();
        let mut warnings = Vec::new();
        let truth_path = dir.join("truth.csv");
        let truth = if truth_path.is_file() {
            match TruthTimes::read(&truth_path) {
                Ok(mut t) => {
                    warnings.append(&mut t.rejected);
                    t
                }
                Err(e) => {
                    warnings.push(e);
                    TruthTimes::default()
                }
            }
        } else {
            TruthTimes::default()
        };
        Ok(ReplayDir {
            dir,
            files,
            truth,
            warnings,
        })
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Number of frame files.
    pub fn len(&self) -> usize {
        self.files.len()
    }

    /// True when there is no frame file (never after a successful `open`).
    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }

    /// Frame files in replay order, with their indices.
    pub fn files(&self) -> &[(u64, PathBuf)] {
        &self.files
    }

    /// Problems found in `truth.csv` when opening (its frames fall back to
    /// point timestamps).
    pub fn warnings(&self) -> &[ReplayError] {
        &self.warnings
    }

    /// True when `truth.csv` gave at least one row.
    pub fn has_truth(&self) -> bool {
        !self.truth.times.is_empty()
    }

    /// The recorded frame period (median of the `truth.csv` scan-end steps), if known.
    pub fn recorded_period_s(&self) -> Option<f64> {
        self.truth.median_period_s()
    }

    /// Reads the `k`-th frame file in replay order (`None` past the end).
    ///
    /// # Errors
    /// [`ReplayError::Frame`] for an unreadable or corrupt file,
    /// [`ReplayError::NoTimestamps`] when no scan time can be found.
    pub fn read(&self, k: usize) -> Option<Result<ReplayFrame, ReplayError>> {
        let (index, path) = self.files.get(k)?;
        Some(self.read_file(*index, path))
    }

    /// Every frame in order; errors are yielded in place (skip them to go on).
    pub fn iter(&self) -> impl Iterator<Item = Result<ReplayFrame, ReplayError>> + '_ {
        (0..self.files.len()).filter_map(|k| self.read(k))
    }

    fn read_file(&self, index: u64, path: &Path) -> Result<ReplayFrame, ReplayError> {
        let points = read_cloud(path).map_err(|source| ReplayError::Frame {
            path: path.to_owned(),
            source,
        })?;
        let (times, time_source) = match self.truth.times.get(&index) {
            Some(t) => (*t, TimeSource::TruthCsv),
            None => (
                times_from_points(&points)
                    .ok_or_else(|| ReplayError::NoTimestamps(path.to_owned()))?,
                TimeSource::PointTimestamps,
            ),
        };
        Ok(ReplayFrame {
            index,
            path: path.to_owned(),
            points,
            scan_start_s: times.scan_start_s,
            scan_end_s: times.scan_end_s,
            time_source,
        })
    }
}

/// `frame_<digits>.pcd` / `.ply` (extension in any case) → the index.
fn frame_index(path: &Path) -> Option<u64> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    if ext != "pcd" && ext != "ply" {
        return None;
    }
    let digits = path.file_stem()?.to_str()?.strip_prefix("frame_")?;
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    digits.parse().ok()
}

/// Smallest and largest finite timestamp.
fn times_from_points(points: &[Point]) -> Option<ScanTimes> {
    let mut it = points.iter().map(|p| p.t).filter(|t| t.is_finite());
    let first = it.next()?;
    let (lo, hi) = it.fold((first, first), |(lo, hi), t| (lo.min(t), hi.max(t)));
    Some(ScanTimes {
        scan_start_s: lo,
        scan_end_s: hi,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_names_are_recognised() {
        assert_eq!(frame_index(Path::new("a/frame_000042.pcd")), Some(42));
        assert_eq!(frame_index(Path::new("frame_7.PLY")), Some(7));
        assert_eq!(frame_index(Path::new("frame_.pcd")), None);
        assert_eq!(frame_index(Path::new("frame_12a.pcd")), None);
        assert_eq!(frame_index(Path::new("frame_000001.txt")), None);
        assert_eq!(frame_index(Path::new("truth.csv")), None);
    }
}
