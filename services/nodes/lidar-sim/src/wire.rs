//! A simulated frame on the wire: its truth, its cloud header and, for the
//! first frame with `truth_init`, the truth acquisition.
//!
//! The sensor process publishes exactly these; a one-process evaluation
//! that feeds the suite's nodes simulated frames calls the same functions,
//! so both hand the suite the same messages.

use spacepose_lidar_sim::Frame;
use spacepose_messages::convert::{pose_to_wire, vector3_to_wire};
use spacepose_messages::{AcquisitionMethod, AcquisitionResult, CloudHeader, Name, TruthMsg};
use spacepose_scenario::TruthState;

/// The truth of frame `sequence` (at its scan end), for the truth topic.
pub fn truth_msg(sequence: u64, truth: &TruthState) -> TruthMsg {
    let mut msg = TruthMsg::new();
    msg.sequence = sequence;
    msg.t_s = truth.t;
    (msg.q_sensor_target, msg.p_sensor_target) = pose_to_wire(&truth.t_sensor_target);
    msg.v_sensor = vector3_to_wire(&truth.v_sensor_target);
    msg.w_target = vector3_to_wire(&truth.w_target);
    msg
}

/// The raw-cloud header of frame `sequence` from sensor `sensor_id`.
pub fn cloud_header(sequence: u64, frame: &Frame, sensor_id: u16) -> CloudHeader {
    let mut header = CloudHeader::new(sequence, frame.scan_start, frame.scan_end);
    header.sensor_id = sensor_id;
    header
}

/// The acquisition `truth_init` publishes before the first frame (sequence
/// 0): a successful `method: truth` at the frame's true pose, signed by
/// `instance`.
pub fn truth_acquisition(first: &Frame, instance: Name) -> AcquisitionResult {
    let mut acq = AcquisitionResult::new();
    acq.method = AcquisitionMethod::Truth as u8;
    acq.success = 1;
    acq.sequence = 0;
    acq.t_s = first.truth.t;
    (acq.q_sensor_target, acq.p_sensor_target) = pose_to_wire(&first.truth.t_sensor_target);
    acq.instance = instance;
    acq
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use spacepose_geometry::{Pose, so3};
    use spacepose_messages::convert::pose_from_wire;

    fn frame() -> Frame {
        let pose = Pose::new(
            so3::exp(&Vector3::new(0.1, -0.2, 0.3)),
            Vector3::new(0.5, -1.0, 12.0),
        );
        Frame {
            points: Vec::new(),
            kinds: Vec::new(),
            scan_start: 2.46,
            scan_end: 3.0,
            truth: TruthState {
                t: 3.0,
                t_sensor_target: pose,
                v_sensor_target: Vector3::new(0.01, 0.0, -0.02),
                w_target: Vector3::new(0.0, 0.05, 0.1),
            },
        }
    }

    #[test]
    fn a_frame_gives_its_truth_header_and_truth_acquisition() {
        let f = frame();
        let t = truth_msg(7, &f.truth);
        assert_eq!((t.sequence, t.t_s), (7, 3.0));
        assert_eq!(
            (t.v_sensor, t.w_target),
            ([0.01, 0.0, -0.02], [0.0, 0.05, 0.1])
        );
        let pose = pose_from_wire(&t.q_sensor_target, &t.p_sensor_target).unwrap();
        assert!((pose.translation - f.truth.t_sensor_target.translation).norm() < 1e-12);
        let r = f.truth.t_sensor_target.rotation;
        assert!((pose.rotation.matrix() - r.matrix()).norm() < 1e-12);

        let h = cloud_header(7, &f, 3);
        assert_eq!(
            (h.sequence, h.scan_start_s, h.scan_end_s, h.sensor_id),
            (7, 2.46, 3.0, 3)
        );

        let a = truth_acquisition(&f, Name::new("sim-a").unwrap());
        assert_eq!(
            (a.method, a.success, a.sequence),
            (AcquisitionMethod::Truth as u8, 1, 0)
        );
        assert_eq!((a.t_s, a.instance.as_str()), (3.0, "sim-a"));
        assert_eq!(
            (a.q_sensor_target, a.p_sensor_target),
            (t.q_sensor_target, t.p_sensor_target)
        );
    }
}
