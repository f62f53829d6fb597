//! The `spacepose-pcd-replay` service: [`PcdReplayNode`] publishes a
//! directory of recorded frames as raw clouds, at a configured rate or at
//! the recorded scan period, optionally in a loop (each pass continues the
//! sensor clock).
//!
//! The directory holds `frame_NNNNNN.pcd` / `.ply` files (as written by
//! `spacepose sim`, or by other tools), read in frame order with
//! [`spacepose_input::PcdDir`]: scan times come from `truth.csv` when
//! present, per-point times from the time field chosen by the configured
//! [`spacepose_input::TimeMapping`], or are derived over the scan interval
//! (a logged warning, never t = 0). A corrupt file is an error value for
//! that frame only: the node logs it, counts it and goes on with the next one.
#![forbid(unsafe_code)]

pub mod config;
pub mod node;
pub mod wire;

pub use config::PcdReplayConfig;
pub use node::PcdReplayNode;
pub use spacepose_input::{InputError, InputFrame, PcdDir};
