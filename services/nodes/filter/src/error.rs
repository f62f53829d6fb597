//! What the filter node refuses or fails at.

use spacepose_filter::FilterError;
use spacepose_messages::MessageError;
use std::path::PathBuf;
use thiserror::Error;

/// A message the node refused, a filter failure, a bad configuration or a
/// snapshot that could not be written or read.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FilterNodeError {
    /// The configuration is invalid (the message names the key).
    #[error("invalid filter service configuration: {0}")]
    Config(String),
    /// A message does not hold what it claims (bad quaternion, unknown
    /// code, non-finite value).
    #[error(transparent)]
    Message(#[from] MessageError),
    /// The filter refused a state or an initialisation.
    #[error(transparent)]
    Filter(#[from] FilterError),
    /// The state snapshot file could not be written or read back (I/O, or
    /// bytes the codec refuses).
    #[error("filter snapshot {path}: {reason}")]
    Snapshot {
        /// The snapshot file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
}
