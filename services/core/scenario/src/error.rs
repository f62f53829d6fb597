//! Errors of the scenario crate.

use thiserror::Error;

/// What can go wrong when configuring a scenario.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ScenarioError {
    /// The scenario name is not one of `slow-spin`, `tumbling`, `ellipse`, `random`.
    #[error("unknown scenario {0:?} (expected slow-spin, tumbling, ellipse or random)")]
    UnknownKind(String),
    /// The frame period is NaN, infinite, zero or negative.
    #[error("frame period must be finite and positive, got {0} s")]
    InvalidFramePeriod(f64),
    /// The time compression is NaN, infinite or below 1.
    #[error("compression must be finite and >= 1, got {0}")]
    InvalidCompression(f64),
    /// The legs' range scale is NaN, infinite or below 1.
    #[error("range_scale must be finite and >= 1, got {0}")]
    InvalidRangeScale(f64),
    /// The range of the random scenario is NaN, infinite, zero or negative.
    #[error("range must be finite and positive, got {0} m")]
    InvalidRange(f64),
    /// The pointing-error amplitude is NaN, infinite, negative or above 5°.
    #[error("pointing error must be finite and in [0, 5] deg, got {0} deg")]
    InvalidPointingError(f64),
    /// The lateral offset of the random scenario is NaN, infinite, negative or above 10°.
    #[error("lateral offset must be finite and in [0, 10] deg, got {0} deg")]
    InvalidLateralOffset(f64),
    /// The random scenario was asked for no frame at all.
    #[error("the random scenario needs at least one frame")]
    NoFrames,
    /// The look-away window is empty or its angle is not in (0, 180] degrees.
    #[error("invalid look-away window: {0}")]
    InvalidLookAway(String),
}
