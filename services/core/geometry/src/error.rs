//! The error type of the geometry crate.

use std::path::PathBuf;

/// Everything that can go wrong in `spacepose-geometry`.
///
/// Bad input (a NaN parameter, an empty cloud, a corrupt file) is reported
/// here; nothing in this crate panics on input data.
#[derive(Debug, thiserror::Error)]
pub enum GeometryError {
    /// The voxel edge length is zero, negative, NaN or infinite.
    #[error("voxel leaf size must be finite and > 0 m, got {0}")]
    InvalidLeafSize(f64),

    /// A point lies so far from the origin (relative to the leaf size) that its
    /// voxel index does not fit the packed 21-bit-per-axis key
    /// (|coordinate / leaf| must stay below 2^20).
    #[error(
        "point ({x}, {y}, {z}) is out of the voxel grid range for leaf size {leaf_size_m} m \
         (|coordinate| / leaf must be < 2^20)"
    )]
    VoxelIndexOutOfRange {
        /// x coordinate of the offending point (m).
        x: f32,
        /// y coordinate of the offending point (m).
        y: f32,
        /// z coordinate of the offending point (m).
        z: f32,
        /// The leaf size in use (m).
        leaf_size_m: f64,
    },

    /// The trim fraction of the trimmed centroid is outside `[0, 0.5)` or NaN.
    #[error("trim fraction must be in [0, 0.5), got {0}")]
    InvalidTrim(f64),

    /// An operation that needs at least one point received none.
    #[error("empty point set")]
    EmptyInput,

    /// An input position has a NaN or infinite coordinate.
    #[error("non-finite position at index {index}")]
    NonFinitePosition {
        /// Index of the first offending point in the input slice.
        index: usize,
    },

    /// The operating system failed to open, read or write a file.
    #[error("I/O error on {path}: {source}")]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying OS error.
        #[source]
        source: std::io::Error,
    },

    /// A point-cloud file is corrupt, truncated or inconsistent with its header.
    #[error("malformed {format} file {path}: {message}")]
    Malformed {
        /// The file concerned.
        path: PathBuf,
        /// `"PCD"` or `"PLY"`.
        format: &'static str,
        /// What is wrong, as precisely as the parser can tell.
        message: String,
    },

    /// A well-formed point-cloud file uses a feature this crate does not read
    /// (e.g. integer coordinates, multi-valued `x`).
    #[error("unsupported {format} file {path}: {message}")]
    Unsupported {
        /// The file concerned.
        path: PathBuf,
        /// `"PCD"` or `"PLY"`.
        format: &'static str,
        /// The unsupported feature.
        message: String,
    },

    /// The file extension is neither `.pcd` nor `.ply`, or does not match the
    /// requested output format.
    #[error("cannot use {path} as a point-cloud file: {message}")]
    BadExtension {
        /// The file concerned.
        path: PathBuf,
        /// Why the extension was rejected.
        message: String,
    },
}
