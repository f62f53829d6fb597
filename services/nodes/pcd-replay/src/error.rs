//! The error type of the replay library.

use spacepose_geometry::GeometryError;
use std::path::PathBuf;

/// Everything that can go wrong while replaying a directory. Only
/// [`ReplayError::Dir`] and [`ReplayError::NoFrames`] stop a replay; the
/// others concern one file, which is reported and skipped.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The directory cannot be listed.
    #[error("cannot list {path}: {source}")]
    Dir {
        /// The directory.
        path: PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },

    /// The directory holds no `frame_NNNNNN.pcd` / `.ply` file.
    #[error("no frame_NNNNNN.pcd or .ply file in {0}")]
    NoFrames(PathBuf),

    /// A frame file cannot be read or is corrupt.
    #[error("frame {path}: {source}")]
    Frame {
        /// The file.
        path: PathBuf,
        /// What the reader found.
        #[source]
        source: GeometryError,
    },

    /// A frame has no scan time: no `truth.csv` row, and no finite timestamp.
    #[error("frame {0}: no truth.csv row and no finite point timestamp")]
    NoTimestamps(PathBuf),

    /// `truth.csv` cannot be read or its header lacks a needed column.
    #[error("truth file {path}: {message}")]
    Truth {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },

    /// One `truth.csv` row is malformed (its frame falls back to the point timestamps).
    #[error("truth file {path}, line {line}: {message}")]
    TruthRow {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
}
