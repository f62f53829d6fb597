//! Geometry for spacepose: the Lie-group maths of the tracking paper
//! (Renaut et al. 2023, "seed 000"), timestamped lidar points, and the
//! point-cloud utilities every service shares.
//!
//! Frame and unit conventions used throughout the project:
//! - SI units (metres, seconds, radians) unless a name says otherwise
//!   (`_deg`, `_ns`, `_cm`).
//! - A [`Pose`] named `t_a_b` maps coordinates expressed in frame `b` into
//!   frame `a`: `x_a = R x_b + p`. The tracker estimates `t_sensor_target`,
//!   the target body frame (origin at the centre of mass) seen from the lidar.
//! - The lidar frame has `z` along the boresight, `x` right, `y` down.
#![forbid(unsafe_code)]

pub mod centroid;
pub mod error;
pub mod euler;
pub mod io;
pub mod point;
pub mod pose;
pub mod so3;
pub mod voxel;

pub use centroid::{DEFAULT_TRIM, HasPosition, centroid, trimmed_centroid};
pub use error::GeometryError;
pub use euler::Euler321;
pub use io::{
    CloudFormat, PointTimes, TimeBase, TimeField, TimeMapping, TimeUnit, TimedCloud, read_cloud,
    read_cloud_timed, write_cloud,
};
pub use point::Point;
pub use pose::Pose;
pub use voxel::{VoxelFilter, VoxelOutput, voxel_filter};
