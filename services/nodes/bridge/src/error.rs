//! Errors of the bridge service.

use thiserror::Error;

/// What can be wrong with a bridge configuration.
#[derive(Debug, Error)]
pub enum BridgeError {
    /// A configuration value is invalid; the message names the field.
    #[error("invalid bridge configuration: {0}")]
    InvalidConfig(String),
}
