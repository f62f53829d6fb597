//! `pose()` and `set_pose()` on every message that carries `t_sensor_target`
//! (quaternion w, x, y, z; position m), through the pose conversions of
//! [`super`].

use super::{pose_from_wire, pose_to_wire};
use crate::error::MessageError;
use crate::{AcquisitionResult, Command, FilterState, PoseEstimate, TruthMsg};
use spacepose_geometry::Pose;

macro_rules! pose_access {
    ($($ty:ty),*) => {$(
        impl $ty {
            /// The carried `t_sensor_target` as a geometry pose (checked).
            pub fn pose(&self) -> Result<Pose, MessageError> {
                pose_from_wire(&self.q_sensor_target, &self.p_sensor_target)
            }

            /// Stores `t_sensor_target` (quaternion w, x, y, z; position m).
            pub fn set_pose(&mut self, pose: &Pose) {
                (self.q_sensor_target, self.p_sensor_target) = pose_to_wire(pose);
            }
        }
    )*};
}

pose_access!(
    PoseEstimate,
    FilterState,
    AcquisitionResult,
    TruthMsg,
    Command
);
