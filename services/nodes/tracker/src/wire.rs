//! What the tracker puts on the wire: its answer for a frame as a
//! `PoseEstimate`. (The messages it reads are converted by
//! `spacepose_messages::convert`; the mode travels as [`TrackingMode::code`].)

use spacepose_messages::convert::matrix_to_wire;
use spacepose_messages::{CloudHeader, Name, PoseEstimate, WireStatus};
use spacepose_tracker::{TrackOutput, TrackStatus, TrackingMode};

/// The wire code of a track status.
pub fn status_to_wire(status: TrackStatus) -> WireStatus {
    match status {
        TrackStatus::Tracking => WireStatus::Tracking,
        TrackStatus::Degraded => WireStatus::Degraded,
        TrackStatus::Lost => WireStatus::Lost,
        TrackStatus::Unconfirmed => WireStatus::Unconfirmed,
    }
}

/// The track status of a wire code ([`status_to_wire`] back).
pub fn status_from_wire(status: WireStatus) -> TrackStatus {
    match status {
        WireStatus::Tracking => TrackStatus::Tracking,
        WireStatus::Degraded => TrackStatus::Degraded,
        WireStatus::Lost => TrackStatus::Lost,
        WireStatus::Unconfirmed => TrackStatus::Unconfirmed,
    }
}

/// An estimate for the frame of `header`, status `lost`, identity pose:
/// the starting point of every published estimate (`published_ns` is
/// stamped by the publisher).
pub fn lost_estimate(header: &CloudHeader, instance: Name, mode: TrackingMode) -> PoseEstimate {
    let mut e = PoseEstimate::new();
    e.status = WireStatus::Lost as u8;
    e.mode = mode.code();
    e.sequence = header.sequence;
    e.t_s = header.scan_end_s;
    e.instance = instance;
    e.cloud_published_ns = header.published_ns;
    e
}

/// Fills `e` from the tracker's answer for the frame: pose, status,
/// covariance (zeros when unknown), registration figures and timings.
///
/// A frame without a measurement ([`TrackOutput::has_measurement`] false:
/// too few points, e.g. the target out of view, or a failed registration)
/// is `lost` with `iterations == 0`, `inliers == 0`, `cost == 0` and an
/// all-zero covariance, and its pose is the filter prediction at `t_s`, not
/// a measurement: the filter service fuses only `tracking` estimates.
pub fn fill_estimate(e: &mut PoseEstimate, out: &TrackOutput) {
    e.status = status_to_wire(out.status) as u8;
    e.t_s = out.t;
    e.set_pose(&out.t_sensor_target);
    e.covariance = out
        .covariance
        .as_ref()
        .map_or([[0.0; 6]; 6], matrix_to_wire);
    e.iterations = saturating_u32(out.iterations());
    e.held_axes = u8::try_from(out.held_axes().min(3)).unwrap_or(3);
    e.held_translations = u8::try_from(out.held_translations().min(3)).unwrap_or(3);
    if let Some(r) = &out.registration {
        e.cost = r.cost.mean;
        e.inliers = saturating_u32(r.inliers);
    }
    e.points_used = saturating_u32(out.points_used);
    e.preprocess_ms = out.timings.preprocess_ms;
    e.registration_ms = out.timings.registration_ms;
    e.total_ms = out.timings.total_ms;
}

fn saturating_u32(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix6, Vector3};
    use spacepose_geometry::{Pose, so3};
    use spacepose_messages::mode_from_code;
    use spacepose_tracker::Timings;

    #[test]
    fn modes_and_statuses_map_one_to_one() {
        for m in TrackingMode::ALL {
            let code = m.code();
            assert_eq!(mode_from_code(code).unwrap(), m);
            assert_eq!(mode_from_code(code).unwrap().as_str(), m.as_str());
        }
        assert!(mode_from_code(TrackingMode::MAX_CODE + 1).is_err());
        for s in [
            TrackStatus::Tracking,
            TrackStatus::Degraded,
            TrackStatus::Lost,
            TrackStatus::Unconfirmed,
        ] {
            assert_eq!(status_to_wire(s).as_str(), s.as_str());
            assert_eq!(status_from_wire(status_to_wire(s)), s);
        }
    }

    #[test]
    fn outputs_become_estimates_of_their_frame() {
        let mut header = CloudHeader::new(42, 9.0, 10.0);
        header.published_ns = 123;
        let instance = Name::new("tracker-a").unwrap();
        let mut e = lost_estimate(&header, instance, TrackingMode::CtNdt);
        assert_eq!(e.wire_status().unwrap(), WireStatus::Lost);
        assert_eq!((e.sequence, e.t_s, e.cloud_published_ns), (42, 10.0, 123));
        assert_eq!(e.mode, TrackingMode::CtNdt.code());
        let pose = Pose::new(
            so3::exp(&Vector3::new(0.1, 0.2, 0.3)),
            Vector3::new(1.0, 2.0, 30.0),
        );
        let out = TrackOutput {
            t: 10.0,
            t_sensor_target: pose,
            covariance: Some(Matrix6::identity() * 1e-4),
            status: TrackStatus::Degraded,
            reason: "test".into(),
            registration: None,
            innovation_rot_deg: 0.0,
            innovation_pos_m: 0.0,
            nis: f64::NAN,
            w_target: Vector3::zeros(),
            v_sensor: Vector3::zeros(),
            points_in: 1000,
            points_used: 400,
            timings: Timings {
                preprocess_ms: 1.0,
                registration_ms: 2.0,
                total_ms: 3.5,
            },
            fallback: false,
            start_up: false,
            points_behind: 0,
            refit: false,
            held: None,
        };
        fill_estimate(&mut e, &out);
        assert_eq!(e.wire_status().unwrap(), WireStatus::Degraded);
        let (angle, dist) = e.pose().unwrap().error_to(&pose);
        assert!(angle < 1e-12 && dist < 1e-12);
        assert_eq!((e.covariance[5][5], e.covariance[0][1]), (1e-4, 0.0));
        assert_eq!((e.points_used, e.total_ms), (400, 3.5));
        assert_eq!(e.instance.as_str(), "tracker-a");
    }
}
