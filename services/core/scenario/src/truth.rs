//! Ground truth of the relative state at one instant.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use spacepose_geometry::Pose;

/// Ground truth of the relative state at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TruthState {
    /// Time on the sensor clock (s).
    pub t: f64,
    /// Target body frame (origin at the centre of mass) → sensor frame.
    pub t_sensor_target: Pose,
    /// Velocity of the target centre of mass relative to the sensor, in the
    /// sensor frame (m/s): the time derivative of
    /// `t_sensor_target.translation`, the sensor's own rotation included.
    pub v_sensor_target: Vector3<f64>,
    /// Angular velocity of the target relative to the sensor, in the target
    /// body frame (rad/s): `R(t + dt) ≈ R(t) Exp(ω dt)` with `R` the rotation
    /// of `t_sensor_target` — the ω of seed 000 Eq. (9).
    pub w_target: Vector3<f64>,
}

impl TruthState {
    /// The same angular velocity expressed in the sensor frame, `R ω`, so
    /// that `R(t + dt) ≈ Exp(R ω dt) R(t)`.
    pub fn w_sensor(&self) -> Vector3<f64> {
        self.t_sensor_target.rotation * self.w_target
    }

    /// True when every number is finite.
    pub fn is_finite(&self) -> bool {
        self.t.is_finite()
            && self.t_sensor_target.is_finite()
            && self.v_sensor_target.iter().all(|v| v.is_finite())
            && self.w_target.iter().all(|v| v.is_finite())
    }

    /// First-order prediction of the pose `dt` seconds later, with constant
    /// velocities: `(R Exp(ω dt), p + v dt)`.
    pub fn extrapolate(&self, dt: f64) -> Pose {
        let r = self.t_sensor_target.rotation * spacepose_geometry::so3::exp(&(self.w_target * dt));
        Pose::new(
            r,
            self.t_sensor_target.translation + self.v_sensor_target * dt,
        )
    }
}
