//! Chaser trajectory + target attitude + sensor pointing → the relative state
//! in the sensor frame.

use crate::attitude::TargetAttitude;
use crate::chaser::ChaserTrajectory;
use crate::pointing::{PointingError, look_at, look_at_with_rate};
use crate::scenario::{Scenario, evenly_spaced_end_times};
use crate::truth::TruthState;
use nalgebra::{Rotation3, Vector3};
use spacepose_geometry::{Pose, so3};

/// A continuous relative-motion scenario (slow-spin, tumbling, ellipse).
#[derive(Debug, Clone)]
pub struct RelativeMotion {
    pub(crate) name: &'static str,
    pub(crate) trajectory: ChaserTrajectory,
    pub(crate) attitude: TargetAttitude,
    pub(crate) pointing: PointingError,
    pub(crate) compression: f64,
    pub(crate) frame_period_s: f64,
}

impl RelativeMotion {
    /// `R_lvlh_sensor(t)`: look at the target, then the pointing error.
    pub(crate) fn sensor_in_lvlh(&self, t: f64) -> Rotation3<f64> {
        let (p_chaser, _) = self.trajectory.state(self.compression * t);
        look_at(&(-p_chaser), &self.trajectory.sensor_down_reference()) * self.pointing.rotation(t)
    }

    /// `R_lvlh_sensor(t)` and the sensor's angular velocity relative to LVLH
    /// in the sensor frame, analytically: for `R = L E` (look-at, then
    /// pointing error), `ω = Eᵀ ω_L + ω_E`.
    fn sensor_in_lvlh_with_rate(&self, t: f64) -> (Rotation3<f64>, Vector3<f64>) {
        let (p_chaser, v_chaser) = self.trajectory.state(self.compression * t);
        let (look, w_look) = look_at_with_rate(
            &(-p_chaser),
            &(-v_chaser * self.compression),
            &self.trajectory.sensor_down_reference(),
        );
        let (error, w_error) = self.pointing.rotation_and_rate(t);
        (look * error, error.inverse() * w_look + w_error)
    }

    /// `R_lvlh_target(t)` and the target's inertial rate (body frame).
    pub(crate) fn target_in_lvlh(&self, t: f64) -> (Rotation3<f64>, Vector3<f64>) {
        let (r_inertial_target, w_target) = self.attitude.at(t);
        let r_inertial_lvlh = so3::exp(&(self.trajectory.lvlh_rate() * (self.compression * t)));
        (r_inertial_lvlh.inverse() * r_inertial_target, w_target)
    }

    fn pose_from(&self, t: f64, r_lvlh_sensor: &Rotation3<f64>) -> Pose {
        let (p_chaser, _) = self.trajectory.state(self.compression * t);
        let (r_lvlh_target, _) = self.target_in_lvlh(t);
        let r_sensor_lvlh = r_lvlh_sensor.inverse();
        // The target CoM is the LVLH origin.
        Pose::new(r_sensor_lvlh * r_lvlh_target, r_sensor_lvlh * (-p_chaser))
    }
}

impl Scenario for RelativeMotion {
    fn name(&self) -> &str {
        self.name
    }

    fn duration_s(&self) -> f64 {
        self.trajectory.duration() / self.compression
    }

    fn frame_end_times(&self, frames: usize) -> Vec<f64> {
        evenly_spaced_end_times(self.frame_period_s, frames)
    }

    fn state_at(&self, t: f64) -> TruthState {
        let c = self.compression;
        let (_, v_chaser_per_tau) = self.trajectory.state(c * t);
        let v_chaser = v_chaser_per_tau * c;
        let (r_lvlh_sensor, w_sensor_lvlh) = self.sensor_in_lvlh_with_rate(t);
        let pose = self.pose_from(t, &r_lvlh_sensor);
        let (r_lvlh_target, w_target_inertial) = self.target_in_lvlh(t);
        let w_lvlh = self.trajectory.lvlh_rate() * c;
        // d/dt (R_lsᵀ (−p_c)) = −ω_s × p_s − R_lsᵀ ṗ_c.
        let v = -w_sensor_lvlh.cross(&pose.translation) - r_lvlh_sensor.inverse() * v_chaser;
        // R_st = R_lsᵀ R_il(τ)ᵀ R_it: subtract the sensor's and LVLH's rates,
        // brought into the body frame.
        let w = w_target_inertial
            - pose.rotation.inverse() * w_sensor_lvlh
            - r_lvlh_target.inverse() * w_lvlh;
        TruthState {
            t,
            t_sensor_target: pose,
            v_sensor_target: v,
            w_target: w,
        }
    }

    fn pose_at(&self, t: f64) -> Pose {
        self.pose_from(t, &self.sensor_in_lvlh(t))
    }

    fn frame_period_s(&self) -> f64 {
        self.frame_period_s
    }
}
