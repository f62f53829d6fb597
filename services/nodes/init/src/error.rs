//! Errors of the init service.

use thiserror::Error;

/// What can go wrong in the init service's library.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum InitError {
    /// A configuration value is out of range, NaN, or names an unavailable method.
    #[error("invalid init configuration: {0}")]
    InvalidConfig(String),
    /// An acquisition method could not run on this frame (too few points,
    /// bad input); the attempt counts as a failure, never as a success.
    #[error("{method}: {reason}")]
    Method {
        /// The method's name (`template-matching`, `cnn`).
        method: &'static str,
        /// Why it failed.
        reason: String,
    },
    /// An acquisition method could not be built (model, target, sensor).
    #[error("building {method}: {reason}")]
    Build {
        /// The method's name.
        method: &'static str,
        /// Why it could not be built.
        reason: String,
    },
    /// A message from the bus was malformed (bad code, non-finite value).
    #[error("invalid {what}: {reason}")]
    InvalidMessage {
        /// The message type.
        what: &'static str,
        /// What is wrong with it.
        reason: String,
    },
}
