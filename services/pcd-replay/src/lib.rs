//! Replay of recorded lidar frames for spacepose: a directory of
//! `frame_NNNNNN.pcd` / `.ply` files (as written by `spacepose sim`) read in
//! frame order with [`spacepose_geometry::read_cloud`]. Scan times come from
//! `truth.csv` when present, otherwise from the point timestamps. A corrupt
//! file is an error value for that frame only: the caller reports it and
//! goes on with the next one.
//!
//! A library only: the `spacepose-pcd-replay` binary publishes the frames.
#![forbid(unsafe_code)]

pub mod error;
pub mod replay;
pub mod truth;

pub use error::ReplayError;
pub use replay::{ReplayDir, ReplayFrame, TimeSource};
pub use truth::{ScanTimes, TruthTimes};

#[cfg(test)]
mod replay_tests;
