//! Errors of the telemetry service.

use thiserror::Error;

/// What can go wrong turning messages into telemetry.
#[derive(Debug, Error)]
pub enum TelemetryError {
    /// A message could not be converted (unknown code, bad quaternion).
    #[error("invalid {what} message: {source}")]
    InvalidMessage {
        /// Which message.
        what: &'static str,
        /// Why.
        source: spacepose_messages::MessageError,
    },
    /// JSON serialisation failed (non-finite numbers are written as `null`,
    /// so this should not happen).
    #[error("JSON encoding: {0}")]
    Json(#[from] serde_json::Error),
    /// A configuration value is invalid.
    #[error("invalid telemetry configuration: {0}")]
    InvalidConfig(String),
}
