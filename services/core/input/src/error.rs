//! The error type of the input crate.

use spacepose_geometry::GeometryError;
use std::path::PathBuf;

/// Everything that can go wrong while reading a recording. Errors returned
/// by [`crate::open`] stop the reading; the ones yielded by
/// [`crate::Recording::frames`] concern one frame or message, and the
/// iteration goes on after them.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    /// The options are invalid (NaN scan period, empty topic or field).
    #[error("invalid input options: {0}")]
    Options(String),

    /// A file or directory cannot be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },

    /// The path is neither a frame directory, an MCAP file nor a ROS 2 bag.
    #[error("{0}: not a frame directory (frame_NNNNNN.pcd/.ply), an .mcap file or a ROS 2 bag")]
    UnknownFormat(PathBuf),

    /// A directory holds no `frame_NNNNNN.pcd` / `.ply` file.
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

    /// A frame has no scan time: no `truth.csv` row, and no finite point
    /// time from its time field.
    #[error("frame {0}: no truth.csv row and no finite point time")]
    NoTimestamps(PathBuf),

    /// `truth.csv` cannot be read or its header lacks a needed column.
    #[error("truth file {path}: {message}")]
    Truth {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },

    /// One `truth.csv` row is malformed (its frame falls back to the point times).
    #[error("truth file {path}, line {line}: {message}")]
    TruthRow {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },

    /// An MCAP file is corrupt or truncated.
    #[error("MCAP file {path}: {message}")]
    Mcap {
        /// The file.
        path: PathBuf,
        /// What the MCAP reader found.
        message: String,
    },

    /// No channel holds point clouds, the wanted topic is absent, or
    /// several point-cloud channels exist and no topic was chosen.
    #[error("{path}: {message}; point-cloud topics: [{topics}]")]
    Topic {
        /// The recording.
        path: PathBuf,
        /// What is wrong.
        message: String,
        /// The point-cloud topics present, with their schemas.
        topics: String,
    },

    /// One message cannot be decoded into points.
    #[error("{topic} message at log time {log_time_ns} ns: {source}")]
    Message {
        /// Its topic.
        topic: String,
        /// Its log time (ns).
        log_time_ns: u64,
        /// What is wrong with it.
        #[source]
        source: CloudError,
    },
}

/// Why one point-cloud message cannot be decoded.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CloudError {
    /// The message ends before a field it must hold.
    #[error("truncated: the message ends inside {0}")]
    Truncated(&'static str),

    /// Big-endian CDR or `is_bigendian` point data (not supported).
    #[error("big-endian {0} is not supported")]
    BigEndian(&'static str),

    /// A CDR encapsulation other than plain little-endian CDR.
    #[error("unsupported CDR encapsulation {0:#06x} (plain little-endian CDR, 0x0001, only)")]
    Encapsulation(u16),

    /// A point field has a datatype code outside 1..=8.
    #[error("field {name:?} has unknown datatype {datatype}")]
    Datatype {
        /// The field.
        name: String,
        /// Its datatype code.
        datatype: u32,
    },

    /// A coordinate is not FLOAT32 or FLOAT64, or a field holds more than one value.
    #[error("field {name:?}: {message}")]
    FieldType {
        /// The field.
        name: String,
        /// What is wrong.
        message: String,
    },

    /// A field `x`, `y` or `z` is missing.
    #[error("no {0} field")]
    MissingField(&'static str),

    /// A field does not fit in one point.
    #[error(
        "field {name:?} at offset {offset} ({size} bytes) does not fit the point step {point_step}"
    )]
    FieldOutsidePoint {
        /// The field.
        name: String,
        /// Its offset in the point (bytes).
        offset: u32,
        /// Its size (bytes).
        size: u32,
        /// Bytes per point.
        point_step: u32,
    },

    /// The declared layout needs more data than the message holds.
    #[error("layout needs {needed} bytes of point data, the message holds {present}")]
    DataTooShort {
        /// Bytes the layout needs.
        needed: u64,
        /// Bytes present.
        present: u64,
    },

    /// The time mapping names a field the cloud does not have.
    #[error("{0}")]
    TimeField(String),

    /// A protobuf or JSON payload cannot be decoded.
    #[error("cannot decode: {0}")]
    Decode(String),
}
