//! The `spacepose-filter` service: [`FilterNode`], the authority on the
//! relative motion, over the filter of `spacepose_filter`.
//!
//! It reads the trackers' `PoseEstimate`s, `AcquisitionResult`s and
//! commands, initialises on an accepted acquisition, fuses one estimate per
//! frame (the primary tracker's, or a standby's when the primary's is
//! missing at the frame deadline, late or unusable: [`selector`]) and
//! publishes the `FilterState` after every change and every
//! `state_period_ms` (heartbeat for late joiners). A `swap` command names
//! the new primary (applied at the next undecided frame). Failover is
//! sticky ([`failover`]): a standby that replaced a missing primary on
//! `promote_after_misses` consecutive frames becomes the acting primary,
//! and the preferred one takes the role back after `revert_after_frames`
//! good frames (logged). The state is persisted after every change
//! ([`snapshot`]) and a restarted filter resumes from it.
#![forbid(unsafe_code)]

pub mod choice;
pub mod config;
pub mod error;
pub mod failover;
pub mod fusion;
pub mod node;
pub mod publication;
pub mod selector;
pub mod snapshot;

#[cfg(test)]
mod restart_tests;

pub use choice::{Candidate, Choice, Offer, Quality, Reason};
pub use config::FilterServiceConfig;
pub use error::FilterNodeError;
pub use failover::{ChangeCause, FailoverPolicy, RoleChange};
pub use fusion::{EstimateOutcome, Fuser, Fusion};
pub use node::FilterNode;
pub use selector::FrameSelector;
