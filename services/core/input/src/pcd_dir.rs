//! A directory of recorded frames (`frame_NNNNNN.pcd` / `.ply`, as written
//! by `spacepose sim`), read in frame order, with `truth.csv` scan times
//! when present.
//!
//! Times of a frame, in order of preference:
//! - scan interval: its `truth.csv` row; else the span of its field times;
//!   else `[index · period, index · period + period]` with the period of
//!   [`InputOptions::scan_period_or`] (configured, else the `truth.csv`
//!   median, else 0.1 s);
//! - point times: the time field ([`spacepose_geometry::read_cloud_timed`]),
//!   relative ones added to the scan start as above; with no field, derived
//!   linearly over the scan interval in point order ([`PointTimes::Derived`]).

use crate::error::InputError;
use crate::frame::{InputFrame, ScanTimeSource, time_span};
use crate::options::InputOptions;
use crate::truth::TruthTimes;
use spacepose_geometry::{PointTimes, read_cloud_timed};
use std::path::{Path, PathBuf};

/// The frames of a directory, sorted by index.
#[derive(Debug)]
pub struct PcdDir {
    dir: PathBuf,
    files: Vec<(u64, PathBuf)>,
    truth: TruthTimes,
    warnings: Vec<InputError>,
    options: InputOptions,
}

impl PcdDir {
    /// Lists `dir` and reads its `truth.csv` if there is one. A corrupt
    /// truth file is reported in [`PcdDir::warnings`], not fatal.
    ///
    /// # Errors
    /// [`InputError::Io`] if `dir` cannot be listed, [`InputError::NoFrames`]
    /// if it holds no frame file.
    pub fn open(dir: impl AsRef<Path>, options: &InputOptions) -> Result<PcdDir, InputError> {
        let dir = dir.as_ref().to_owned();
        let io = |source| InputError::Io {
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
            return Err(InputError::NoFrames(dir));
        }
        files.sort();
        let mut warnings = Vec::new();
        let truth = read_truth(&dir.join("truth.csv"), &mut warnings);
        Ok(PcdDir {
            dir,
            files,
            truth,
            warnings,
            options: options.clone(),
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
    /// point times).
    pub fn warnings(&self) -> &[InputError] {
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
    /// [`InputError::Frame`] for an unreadable or corrupt file,
    /// [`InputError::NoTimestamps`] when a time field holds no finite value
    /// and there is no `truth.csv` row.
    pub fn read(&self, k: usize) -> Option<Result<InputFrame, InputError>> {
        let (index, path) = self.files.get(k)?;
        Some(self.read_file(*index, path))
    }

    /// Every frame in order; errors are yielded in place (skip them to go on).
    pub fn iter(&self) -> impl Iterator<Item = Result<InputFrame, InputError>> + '_ {
        (0..self.files.len()).filter_map(|k| self.read(k))
    }

    fn read_file(&self, index: u64, path: &Path) -> Result<InputFrame, InputError> {
        let cloud =
            read_cloud_timed(path, &self.options.time).map_err(|source| InputError::Frame {
                path: path.to_owned(),
                source,
            })?;
        let truth = self.truth.times.get(&index);
        let period_s = self.options.scan_period_or(self.recorded_period_s());
        let (start_s, end_s) = match truth {
            Some(t) => (t.scan_start_s, t.scan_end_s),
            None => (index as f64 * period_s, (index as f64 + 1.0) * period_s),
        };
        let (points, point_times) = cloud.into_absolute(start_s, (start_s, end_s));
        let (scan, source) = match (truth, &point_times) {
            (Some(_), _) => ((start_s, end_s), ScanTimeSource::TruthCsv),
            (None, PointTimes::Derived) => ((start_s, end_s), ScanTimeSource::ScanPeriod),
            (None, PointTimes::Field(_)) => (
                time_span(&points).ok_or_else(|| InputError::NoTimestamps(path.to_owned()))?,
                ScanTimeSource::PointTimes,
            ),
        };
        Ok(InputFrame {
            index,
            origin: path.display().to_string(),
            frame_id: String::new(),
            points,
            scan_start_s: scan.0,
            scan_end_s: scan.1,
            scan_time_source: source,
            point_times,
            dropped_non_finite: 0,
        })
    }
}

/// `truth.csv` if present; problems go to `warnings`.
fn read_truth(path: &Path, warnings: &mut Vec<InputError>) -> TruthTimes {
    if !path.is_file() {
        return TruthTimes::default();
    }
    match TruthTimes::read(path) {
        Ok(mut t) => {
            warnings.append(&mut t.rejected);
            t
        }
        Err(e) => {
            warnings.push(e);
            TruthTimes::default()
        }
    }
}

/// `frame_<digits>.pcd` / `.ply` (extension in any case) → the index.
pub(crate) fn frame_index(path: &Path) -> Option<u64> {
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

#[cfg(test)]
#[path = "pcd_dir_tests.rs"]
mod tests;
