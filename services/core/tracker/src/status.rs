//! Track status, reported with every frame.

use serde::{Deserialize, Serialize};
use std::fmt;

/// The health of the track after a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TrackStatus {
    /// The registration converged with good quality and agrees with the
    /// filter prediction.
    Tracking,
    /// A pose was produced but its quality is doubtful (no convergence, few
    /// inliers, high cost, or disagreement with the prediction). It is not
    /// fused into the filter; the published pose is the measurement in
    /// `ndt` and `icp` modes and the filter prediction in `deblur` and
    /// `ct-ndt` modes.
    Degraded,
    /// The registration failed, or too many degraded frames in a row: the
    /// track must be re-acquired ([`crate::Tracker::initialize`]).
    Lost,
    /// As `Tracking`, but the acquisition that started the track awaits
    /// its verification. Never from [`crate::Tracker`] itself: the tracker
    /// service publishes its `Tracking` frames so while the init service
    /// has not confirmed the track's acquisition (wire
    /// `Verification::Pending`, `docs/design/acquisition-verification.md`).
    Unconfirmed,
}

impl TrackStatus {
    /// Lower-case name used in logs, JSON and telemetry.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Tracking => "tracking",
            Self::Degraded => "degraded",
            Self::Lost => "lost",
            Self::Unconfirmed => "unconfirmed",
        }
    }
}

impl fmt::Display for TrackStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}
