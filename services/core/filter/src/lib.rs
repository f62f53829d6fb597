//! Relative-motion filter of the spacepose tracker (seed 000 §3.2).
//!
//! - [`position`]: linear Kalman filter on `[p; v]`, constant velocity
//!   (Eq. 8, 10).
//! - [`attitude`]: invariant EKF on `(R, ω, Ω)`: the target's and the
//!   sensor frame's angular velocities, both constant (Eq. 9, 11 with the
//!   sensor frame's turn added), derivation in its module docs.
//! - [`filter`]: [`RelativeMotionFilter`], both filters behind one clock, with
//!   prediction at any time, measurement noise from the registration's
//!   information matrix and a Mahalanobis innovation gate.
//! - [`motion_compensation`]: un-blurring of a scan with the predicted motion
//!   (Eq. 12).
//! - [`config`], [`kalman`] (the shared Kalman step), [`error`].
//!
//! The filter service (`services/nodes/filter`: one estimate per frame,
//! failover, snapshots, wire conversions) is built on this library; the
//! library itself knows nothing of the bus.
//!
//! Units SI. `R = r_sensor_target` (target body → sensor), `p = p_sensor` the
//! target origin in the sensor frame, `v_sensor = dp/dt` in the sensor frame,
//! `w_target` the target's angular velocity relative to the sensor frame, in
//! the target frame.
#![forbid(unsafe_code)]

pub mod attitude;
pub mod config;
pub mod error;
pub mod filter;
pub mod kalman;
pub mod motion_compensation;
mod outputs;
pub mod position;

pub use attitude::{AttitudeFilter, AttitudeNoise, Matrix9};
pub use config::FilterConfig;
pub use error::FilterError;
pub use filter::{RelativeMotionFilter, covariance_from_information};
pub use motion_compensation::MotionCompensation;
pub use outputs::{Prediction, UpdateOutcome};
pub use position::PositionFilter;
