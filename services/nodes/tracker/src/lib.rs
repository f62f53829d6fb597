//! The `spacepose-tracker` service: [`TrackerNode`] over the tracking loop
//! of `spacepose_tracker`, its configuration and its wire conversions.
//!
//! The node follows the target frame after frame: every cropped cloud is
//! registered against the target model and fused into the tracker's local
//! filter, and answered with exactly one `PoseEstimate` (`lost` before
//! initialisation and for bad input). Acquisitions (re)start the track,
//! the filter service's states keep the local filter in step, commands
//! switch the mode or reinitialise. Bad input is logged and counted, never
//! fatal.
#![forbid(unsafe_code)]

pub mod config;
pub mod error;
pub mod frame;
pub mod node;
pub mod track;
pub mod wire;

pub use config::{MapSource, TrackerServiceConfig};
pub use error::ControlError;
pub use frame::{FrameResult, InputIssue};
pub use node::{CommandOutcome, TrackerNode};
