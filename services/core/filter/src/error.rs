//! Errors of the relative-motion filter.

use thiserror::Error;

/// Everything that can go wrong in `spacepose-filter`. Bad input is reported
/// here; it never panics and is never silently replaced by a default.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FilterError {
    /// An input (time, pose, covariance, velocity, config value) contains NaN
    /// or an infinity. `what` names the input.
    #[error("non-finite input: {what}")]
    NonFinite {
        /// Which input was not finite.
        what: &'static str,
    },
    /// A time step was not strictly positive where one is required (an update
    /// at or before the time of the current estimate), or negative where zero
    /// is allowed (a prediction into the past).
    #[error("invalid time step Δt = {dt_s} s")]
    InvalidTimeStep {
        /// The offending step `t - t_filter` (s).
        dt_s: f64,
    },
    /// `predict_at` or `update` was called before `initialize`.
    #[error("the filter is not initialised")]
    NotInitialized,
    /// A covariance (or information) matrix is not symmetric positive
    /// definite. `what` names it.
    #[error("matrix is not symmetric positive definite: {what}")]
    NotPositiveDefinite {
        /// Which matrix failed the check.
        what: &'static str,
    },
    /// A configuration value is out of its valid range.
    #[error("invalid filter configuration: {0}")]
    InvalidConfig(String),
    /// A point handed to motion compensation has a non-finite coordinate,
    /// intensity or timestamp.
    #[error("point {index} is not finite")]
    NonFinitePoint {
        /// Index of the point in the input slice.
        index: usize,
    },
    /// A message from the bus could not be read (bad quaternion, unknown
    /// code, non-finite value); `what` names the message.
    #[error("invalid {what} message: {reason}")]
    InvalidMessage {
        /// Which message was refused.
        what: &'static str,
        /// Why.
        reason: String,
    },
    /// The state snapshot file could not be written or read back (I/O,
    /// or bytes the codec refuses).
    #[error("filter snapshot {path}: {reason}")]
    Snapshot {
        /// The snapshot file.
        path: std::path::PathBuf,
        /// Why.
        reason: String,
    },
}
