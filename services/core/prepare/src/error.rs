//! Errors of package preparation and resolution.

use std::path::PathBuf;

/// What can go wrong when preparing or resolving a target package.
#[derive(Debug, thiserror::Error)]
pub enum PrepareError {
    /// The mesh, the package or the built-in target is unusable.
    #[error(transparent)]
    Target(#[from] spacepose_model::TargetError),
    /// The simulated scenario or lidar could not be set up.
    #[error("simulation: {0}")]
    Simulation(String),
    /// The tracker used for calibration failed to build or run.
    #[error("tracking during calibration: {0}")]
    Tracking(#[from] spacepose_tracker::TrackError),
    /// Too few simulated frames registered well enough to calibrate from
    /// (the target is too small for the sensor at every simulated range,
    /// or the mesh is broken).
    #[error(
        "calibration: only {used} of {frames} simulated frames registered within bounds (need {needed})"
    )]
    TooFewFrames {
        /// Frames simulated.
        frames: usize,
        /// Frames that entered the statistics.
        used: usize,
        /// Frames needed.
        needed: usize,
    },
    /// A file or directory could not be read or written.
    #[error("{path}: {message}")]
    Io {
        /// The path.
        path: PathBuf,
        /// What failed.
        message: String,
    },
    /// An option is out of range (the message names it).
    #[error("invalid option: {0}")]
    InvalidOption(String),
}
