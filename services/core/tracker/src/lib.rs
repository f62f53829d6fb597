//! The tracking loop of seed 000 §3.2-3.3 as a library (no bus): each lidar
//! frame (cropped raw points) goes through the one frame path
//! ([`visibility`]: the points behind the model at the prediction are
//! dropped; [`pipeline`]: motion compensation in the modes that compensate,
//! then the voxel filter), is registered against the smoothed NDT map (or the
//! ICP model), and fused into the relative-motion filter, whose prediction
//! seeds the next frame.
//!
//! Modes ([`TrackingMode`]), named as in seed 000 §4.2:
//! - `ndt`: smoothed NDT, previous pose as the initial guess (Fig. 2);
//! - `deblur`: filter prediction as the guess plus motion compensation of
//!   the cloud with Eq. (12) (Fig. 3);
//! - `ct-ndt`: continuous-time NDT seeded by the filter prediction (Fig. 4);
//! - `icp`: point-to-point ICP, previous pose as the guess (Fig. 2).
//!
//! Every frame yields a [`TrackOutput`] carrying the pose, its covariance,
//! the registration's quality figures, timings and a [`TrackStatus`]
//! (`tracking`, `degraded`, `lost`): loss is reported, never hidden.
//!
//! The `spacepose-tracker` service (`services/nodes/tracker`) runs it on
//! the bus; `spacepose eval tracking` runs that same node in one process.
#![forbid(unsafe_code)]

mod assess;
pub mod config;
mod depth_image;
mod dispatch;
pub mod error;
pub mod held_axes;
pub mod held_rotation;
pub mod innovation;
pub mod length_unit;
mod loss;
pub mod measurement;
pub mod mode;
pub mod model;
pub mod output;
pub mod pipeline;
mod start_up;
pub mod status;
pub mod tracker;
pub mod visibility;

pub use config::{CtStart, LossConfig, TrackerConfig};
pub use error::TrackError;
pub use held_axes::HeldAxes;
pub use held_rotation::{HeldCorrection, HeldRotation, HeldRotationConfig};
pub use length_unit::{REFERENCE_LENGTH_M, map_params_scaled};
pub use mode::TrackingMode;
pub use model::{TargetThresholds, TrackingModel};
pub use output::{Timings, TrackOutput};
pub use pipeline::{FramePipeline, Prepared};
pub use status::TrackStatus;
pub use tracker::Tracker;
pub use visibility::{VisibilityConfig, VisibilityModel};

#[cfg(test)]
mod sim_tests;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod visibility_sim_tests;
