//! The `spacepose-pcd-replay` service: [`PcdReplayNode`] publishes a
//! directory of recorded frames as raw clouds, at a configured rate or at
//! the recorded scan period, optionally in a loop (each pass continues the
//! sensor clock).
//!
//! The directory holds `frame_NNNNNN.pcd` / `.ply` files (as written by
//! `spacepose sim`), read in frame order with
//! [`spacepose_geometry::read_cloud`] ([`replay`]). Scan times come from
//! `truth.csv` when present ([`truth`]), otherwise from the point
//! timestamps. A corrupt file is an error value for that frame only: the
//! node logs it, counts it and goes on with the next one.
#![forbid(unsafe_code)]

pub mod config;
pub mod error;
pub mod node;
pub mod replay;
pub mod truth;
pub mod wire;

pub use config::PcdReplayConfig;
pub use error::ReplayError;
pub use node::PcdReplayNode;
pub use replay::{ReplayDir, ReplayFrame, TimeSource};
pub use truth::{ScanTimes, TruthTimes};

#[cfg(test)]
mod replay_tests;
