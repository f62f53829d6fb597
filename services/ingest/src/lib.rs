//! Ingest for spacepose: the first processing step of every raw lidar frame.
//!
//! 1. Validation: an empty frame, a frame above capacity and a frame whose
//!    points are all non-finite are rejected with an [`IngestError`];
//!    isolated non-finite points are dropped. Everything is counted in
//!    [`IngestStats`].
//! 2. Crop to the target's region of interest ([`Roi`]): the lidar also sees
//!    the test facility (floor, back wall, robot arm), which "would not be
//!    observed in space" and is cropped out (seed 000 §4.1).
//! 3. Voxel filter keeping the mean timestamp per voxel (seed 000 §3.3), so
//!    the continuous-time registration still knows when each point was taken.
//!
//! A library only: the `spacepose-ingest` binary wires it to the bus.
#![forbid(unsafe_code)]

pub mod config;
pub mod error;
pub mod roi;
pub mod stage;
pub mod stats;

pub use config::{AxisBox, DEFAULT_MAX_POINTS, IngestConfig};
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
