//! Errors of the tracking loop.

use spacepose_filter::FilterError;
use spacepose_geometry::GeometryError;
use spacepose_registration::RegistrationError;
use thiserror::Error;

/// Why a frame could not be tracked, or a tracker could not be built.
#[derive(Debug, Error)]
pub enum TrackError {
    /// A configuration value is invalid (NaN, out of range).
    #[error("invalid tracker configuration: {0}")]
    InvalidConfig(String),
    /// `process` was called before `initialize`, or after the track was
    /// lost without re-initialisation.
    #[error("tracker is not initialised (no pose to start from)")]
    NotInitialized,
    /// The frame's scan times are not finite, out of order, or not after
    /// the previous frame.
    #[error("invalid scan times: start {start_s}, end {end_s} (previous end {previous_end_s:?})")]
    InvalidScanTimes {
        /// Scan start (s).
        start_s: f64,
        /// Scan end (s).
        end_s: f64,
        /// End of the previous processed frame (s), if any.
        previous_end_s: Option<f64>,
    },
    /// The voxel filter rejected the frame.
    #[error("pre-processing failed: {0}")]
    Preprocess(#[from] GeometryError),
    /// The registration failed (empty cloud, all NaN, no correspondence,
    /// degenerate geometry).
    #[error("registration failed: {0}")]
    Registration(#[from] RegistrationError),
    /// The filter rejected an input (non-finite pose, bad time step).
    #[error("filter failed: {0}")]
    Filter(#[from] FilterError),
    /// The filter's covariance at a scan start is not positive definite, so
    /// it gives `ct-ndt` no prior on the start pose (or, with
    /// `TrackerConfig::ct_ndt_motion_prior_weight`, on the motion over the scan).
    #[error("no start-pose prior: the filter covariance at t = {t_s} s is not positive definite")]
    NoStartPrior {
        /// Scan start (s).
        t_s: f64,
    },
    /// The target model could not be built or loaded (unknown target, bad
    /// mesh, corrupt or unwritable NDT map file).
    #[error("tracking model: {0}")]
    Model(String),
    /// A message from the bus could not be used (bad quaternion, unknown
    /// code, non-finite value); `what` names the message.
    #[error("invalid {what} message: {reason}")]
    InvalidMessage {
        /// Which message was refused.
        what: &'static str,
        /// Why.
        reason: String,
    },
}
