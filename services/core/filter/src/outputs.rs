//! What the [`RelativeMotionFilter`](crate::RelativeMotionFilter) hands
//! out: its propagated estimate and the outcome of one update.

use crate::attitude::Matrix9;
use nalgebra::{Matrix6, Vector3};
use spacepose_geometry::Pose;

/// The filter's estimate propagated to time `t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction {
    /// Time of the prediction (s, sensor clock).
    pub t: f64,
    /// Predicted `t_sensor_target`.
    pub pose: Pose,
    /// Velocity of the target origin in the sensor frame (m/s).
    pub v_sensor: Vector3<f64>,
    /// Angular velocity of the target relative to the sensor frame, in the
    /// target frame (rad/s): the motion within a scan.
    pub w_target: Vector3<f64>,
    /// Angular velocity of the sensor frame w.r.t. inertial space, in the
    /// sensor frame (rad/s): the chaser's own turn as the filter estimates
    /// it (0 when `FilterConfig::sensor_rate` is off).
    pub w_inertial_sensor: Vector3<f64>,
    /// Pose covariance, `δ = [rot; trans]` in the left-⊕ convention of
    /// Eq. (5) (the convention of the registration).
    pub covariance: Matrix6<f64>,
    /// Full covariance of the attitude filter, `[ξ_R; ξ_u; ξ_Ω]` (`u` =
    /// `w_target`, `Ω` = `w_inertial_sensor`; `crate::attitude`).
    pub attitude_covariance: Matrix9,
    /// Full covariance of the position filter, `[p; v]`.
    pub position_covariance: Matrix6<f64>,
}

impl Prediction {
    /// The angular velocity in the sensor frame, `R ω` (rad/s).
    pub fn w_sensor(&self) -> Vector3<f64> {
        self.pose.rotation * self.w_target
    }
}

/// What [`RelativeMotionFilter::update`](crate::RelativeMotionFilter::update)
/// did with a measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UpdateOutcome {
    /// Angle of the attitude innovation `Log(R̄ R̂⁻ᵀ)` (deg).
    pub innovation_rot_deg: f64,
    /// Norm of the position innovation `p̄ - p̂⁻` (m).
    pub innovation_pos_m: f64,
    /// Squared Mahalanobis distance of the 6-D innovation.
    pub mahalanobis2: f64,
    /// The gate it was compared to (`None`: no gate).
    pub gate_mahalanobis2: Option<f64>,
    /// True when the measurement is consistent with the prediction (inside
    /// the gate, or no gate configured).
    pub accepted: bool,
    /// True when the measurement was fused into the state.
    pub fused: bool,
    /// True when the registration's covariance was used as measurement noise
    /// (false: the configured fixed noise).
    pub used_registration_covariance: bool,
    /// Number of measurements rejected in a row, including this one.
    pub consecutive_rejections: u32,
}
