//! Ingest for spacepose: the first processing step of every raw lidar frame.
//!
//! 1. Validation: a frame above capacity, a frame whose points are all
//!    non-finite and a frame whose scan interval is non-finite or reversed
//!    are rejected with an [`IngestError`]; isolated non-finite points are
//!    dropped. Everything is counted in [`IngestStats`].
//! 2. Crop to the target's region of interest ([`Roi`]): the lidar also sees
//!    the test facility (floor, back wall, robot arm), which "would not be
//!    observed in space" and is cropped out (seed 000 §4.1).
//!
//! Ingest does not voxel-filter: the tracker motion-compensates the raw
//! points of each frame before its voxel filter (the one frame path,
//! `spacepose_tracker::pipeline`), and the init service voxel-filters what
//! it acquires on. A voxel's mean point cannot be compensated by its mean
//! timestamp, so a voxel filter here would come before the compensation.
//!
//! # "Target not seen" is an observation, not bad input
//!
//! A frame the sensor delivered correctly (valid header: finite, ordered
//! scan interval) that holds no point at all, or no (or too few) points of
//! the target after the crop, is forwarded downstream with its own header
//! (sequence, scan start and end) and zero (or few) points, and counted in
//! [`IngestStats::empty_frames`] / [`IngestStats::frames_without_target`];
//! it is not rejected. Reason (issue 5, decided by the lead): when the
//! target leaves the field of view, the raw frames are empty (the sensor
//! looked away and saw nothing). Dropping them as bad input starved the
//! tracker: no cloud reached it during the gap, so it could not report
//! `lost` until the first frame after the target's return, and the init
//! service could only start acquiring then. Forwarded, each frame of the
//! gap gets its `lost` estimate at once (the tracker declares a cloud below
//! its minimum point count lost immediately, without fusing anything), and
//! the init service acquires on the first frame with enough points.
//! Genuinely bad input (non-finite coordinates, a bad scan interval, a
//! frame above capacity, a wrong schema refused by the bus) is still
//! rejected and counted under its own reason.
//!
//! A library only: the `spacepose-ingest` binary wires it to the bus.
#![forbid(unsafe_code)]

pub mod background;
pub mod config;
pub mod detect;
pub mod error;
pub mod roi;
pub mod stage;
pub mod stats;

pub use background::BackgroundPlane;
pub use config::{AxisBox, DEFAULT_MAX_POINTS, DetectConfig, IngestConfig};
pub use detect::{Detection, detect};
pub use error::IngestError;
pub use roi::{AttitudePrediction, PredictionIssue, Roi, RoiKind, TargetPrediction};
pub use stage::{CropCounts, FrameReport, IngestStage, crop_into};
pub use stats::IngestStats;

#[cfg(test)]
mod clutter_tests;
#[cfg(test)]
mod fuzz_tests;
#[cfg(test)]
mod stage_tests;
