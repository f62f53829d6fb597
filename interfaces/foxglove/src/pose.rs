//! Poses as `foxglove.PoseInFrame` and `foxglove.FrameTransform`.
//!
//! The suite's poses are `t_sensor_target` (target body -> sensor) with a
//! scalar-first quaternion `[w, x, y, z]`; Foxglove's are `x, y, z, w`.
//! A pose in frame `sensor` and a transform from parent `sensor` to child
//! `target` both carry `t_sensor_target` as it is.

use crate::stamp::timestamp;
use crate::topics::SENSOR_FRAME;
use foxglove::messages::{FrameTransform, Pose, PoseInFrame, PosesInFrame, Quaternion, Vector3};

/// A rigid pose `t_sensor_target` at sensor time `t_s` (s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorPose {
    /// Time of validity (s, sensor clock).
    pub t_s: f64,
    /// Rotation, unit quaternion `[w, x, y, z]`.
    pub q_sensor_target: [f64; 4],
    /// Position of the target origin in the sensor frame (m).
    pub p_sensor_target: [f64; 3],
}

impl SensorPose {
    fn pose(&self) -> Pose {
        Pose {
            position: Some(vector(self.p_sensor_target)),
            orientation: Some(quaternion(self.q_sensor_target)),
        }
    }

    /// The pose in frame `sensor`.
    pub fn pose_in_frame(&self) -> PoseInFrame {
        PoseInFrame {
            timestamp: Some(timestamp(self.t_s)),
            frame_id: SENSOR_FRAME.to_string(),
            pose: Some(self.pose()),
        }
    }

    /// The transform from `sensor` (parent) to `child` (the target frame).
    pub fn transform_to(&self, child: &str) -> FrameTransform {
        FrameTransform {
            timestamp: Some(timestamp(self.t_s)),
            parent_frame_id: SENSOR_FRAME.to_string(),
            child_frame_id: child.to_string(),
            translation: Some(vector(self.p_sensor_target)),
            rotation: Some(quaternion(self.q_sensor_target)),
        }
    }
}

/// A trajectory: `poses` (oldest first) in frame `sensor`, stamped at the
/// newest pose's time (0 s when there is none).
pub fn poses_in_frame<'a>(poses: impl IntoIterator<Item = &'a SensorPose>) -> PosesInFrame {
    let mut t_s = 0.0;
    let poses = poses
        .into_iter()
        .map(|p| {
            t_s = p.t_s;
            p.pose()
        })
        .collect();
    PosesInFrame {
        timestamp: Some(timestamp(t_s)),
        frame_id: SENSOR_FRAME.to_string(),
        poses,
    }
}

fn vector(p: [f64; 3]) -> Vector3 {
    Vector3 {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

fn quaternion(q_wxyz: [f64; 4]) -> Quaternion {
    Quaternion {
        x: q_wxyz[1],
        y: q_wxyz[2],
        z: q_wxyz[3],
        w: q_wxyz[0],
    }
}

impl From<&spacepose_messages::PoseEstimate> for SensorPose {
    fn from(m: &spacepose_messages::PoseEstimate) -> Self {
        Self {
            t_s: m.t_s,
            q_sensor_target: m.q_sensor_target,
            p_sensor_target: m.p_sensor_target,
        }
    }
}

impl From<&spacepose_messages::TruthMsg> for SensorPose {
    fn from(m: &spacepose_messages::TruthMsg) -> Self {
        Self {
            t_s: m.t_s,
            q_sensor_target: m.q_sensor_target,
            p_sensor_target: m.p_sensor_target,
        }
    }
}

impl From<&spacepose_messages::FilterState> for SensorPose {
    fn from(m: &spacepose_messages::FilterState) -> Self {
        Self {
            t_s: m.t_s,
            q_sensor_target: m.q_sensor_target,
            p_sensor_target: m.p_sensor_target,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use foxglove::{Decode, Encode};
    use spacepose_messages::PoseEstimate;

    fn round_trip<T: Encode + Decode + PartialEq + std::fmt::Debug>(m: &T) -> T {
        let mut buf = Vec::new();
        m.encode(&mut buf).unwrap();
        let back = T::decode(buf.as_slice()).unwrap();
        assert_eq!(&back, m);
        back
    }

    #[test]
    fn a_trajectory_is_stamped_at_its_newest_pose() {
        let at = |t_s: f64| SensorPose {
            t_s,
            q_sensor_target: [1.0, 0.0, 0.0, 0.0],
            p_sensor_target: [0.0, 0.0, t_s],
        };
        let track = round_trip(&poses_in_frame(&[at(1.0), at(1.5)]));
        assert_eq!(track.frame_id, "sensor");
        assert_eq!(track.timestamp.unwrap().total_nanos(), 1_500_000_000);
        let z: Vec<f64> = track.poses.iter().map(|p| p.position.unwrap().z).collect();
        assert_eq!(z, [1.0, 1.5]);
        assert!(poses_in_frame(&[]).poses.is_empty());
    }

    #[test]
    fn an_estimate_becomes_a_pose_and_a_transform_in_the_sensor_frame() {
        let mut m = PoseEstimate::new();
        m.t_s = 2.5;
        m.q_sensor_target = [0.5, 0.5, -0.5, 0.5];
        m.p_sensor_target = [0.1, -0.2, 30.0];
        let pose = round_trip(&SensorPose::from(&m).pose_in_frame());
        assert_eq!(pose.frame_id, "sensor");
        let p = pose.pose.unwrap();
        let q = p.orientation.unwrap();
        assert_eq!([q.w, q.x, q.y, q.z], m.q_sensor_target);
        let v = p.position.unwrap();
        assert_eq!([v.x, v.y, v.z], m.p_sensor_target);
        assert_eq!(pose.timestamp.unwrap().total_nanos(), 2_500_000_000);
        let tf = round_trip(&SensorPose::from(&m).transform_to("target"));
        assert_eq!(
            (tf.parent_frame_id.as_str(), tf.child_frame_id.as_str()),
            ("sensor", "target")
        );
        let r = tf.rotation.unwrap();
        assert_eq!([r.w, r.x, r.y, r.z], m.q_sensor_target);
        let t = tf.translation.unwrap();
        assert_eq!([t.x, t.y, t.z], m.p_sensor_target);
    }
}
