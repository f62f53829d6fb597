//! The filter state persisted to a file, so that a restarted filter service
//! resumes from its predecessor's state instead of starting uninitialised
//! and fusing nothing until the next acquisition (issue 7, redundancy).
//!
//! The file holds one `FilterState` in the suite's postcard codec (magic,
//! schema version, kind, size checks), written atomically (temporary file
//! then rename) after every state change. It is only used when it is fresh:
//! written less than `max_age` ago (wall clock, file modification time);
//! an older one may belong to another run.

use crate::error::FilterNodeError;
use spacepose_messages::{FilterState, decode, encode};
use std::path::Path;
use std::time::Duration;

fn snapshot_error(path: &Path, reason: impl ToString) -> FilterNodeError {
    FilterNodeError::Snapshot {
        path: path.to_path_buf(),
        reason: reason.to_string(),
    }
}

/// Writes `state` to `path` atomically.
pub fn save_snapshot(path: &Path, state: &FilterState) -> Result<(), FilterNodeError> {
    let bytes = encode(state).map_err(|e| snapshot_error(path, e))?;
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, bytes).map_err(|e| snapshot_error(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| snapshot_error(path, e))
}

/// The state in `path` when the file exists and was written less than
/// `max_age` ago; `Ok(None)` when it is missing or too old. A file that
/// cannot be read or decoded is an error (the caller logs it and starts
/// without it).
pub fn load_snapshot(
    path: &Path,
    max_age: Duration,
) -> Result<Option<FilterState>, FilterNodeError> {
    let meta = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(snapshot_error(path, e)),
    };
    let age = meta
        .modified()
        .map_err(|e| snapshot_error(path, e))?
        .elapsed()
        .unwrap_or(Duration::ZERO);
    if age > max_age {
        return Ok(None);
    }
    let bytes = std::fs::read(path).map_err(|e| snapshot_error(path, e))?;
    decode::<FilterState>(&bytes)
        .map(Some)
        .map_err(|e| snapshot_error(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fresh_snapshot_round_trips_and_an_old_or_corrupt_one_does_not() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("filter.state");
        assert_eq!(load_snapshot(&path, Duration::from_secs(5)).unwrap(), None);
        let mut s = FilterState::new();
        s.initialized = 1;
        s.t_s = 12.5;
        s.w_target = [0.1, -0.2, 0.3];
        save_snapshot(&path, &s).unwrap();
        let back = load_snapshot(&path, Duration::from_secs(5))
            .unwrap()
            .unwrap();
        assert_eq!(back, s);
        std::thread::sleep(Duration::from_millis(20));
        assert_eq!(
            load_snapshot(&path, Duration::from_millis(10)).unwrap(),
            None
        );
        std::fs::write(&path, b"SPgarbage").unwrap();
        let e = load_snapshot(&path, Duration::from_secs(5)).unwrap_err();
        assert!(e.to_string().contains("filter.state"), "{e}");
    }
}
