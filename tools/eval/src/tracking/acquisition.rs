//! An acquisition scored against the truth: correct, false accept or
//! rejected, with the eval's one far-off bound
//! ([`super::bounds::far_off`]). An accepted pose beyond it hands the tracker a wrong
//! start: a false accept.

use super::bounds::{far_off, pose_error};
use nalgebra::Rotation3;
use serde::Serialize;
use spacepose_geometry::Pose;
use spacepose_messages::{AcquisitionMethod, AcquisitionResult};

/// One acquisition init published.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AcquisitionRecord {
    /// Frame it was computed on.
    pub frame: u64,
    /// `cnn`, `template-matching`, `given`, `truth`.
    pub method: String,
    /// Whether its checks accepted it.
    pub accepted: bool,
    /// Its f_CONV (m²).
    pub f_conv_m2: f64,
    /// Compute time (ms).
    pub time_ms: f64,
    /// Attitude error against the truth (deg, d_sym over the target's
    /// symmetry group), when the truth is known.
    pub ang_err_deg: Option<f64>,
    /// Position error (m), when the truth is known.
    pub pos_err_m: Option<f64>,
    /// `correct`, `false-accept`, `rejected`, or `unscored` (no truth).
    pub verdict: &'static str,
}

/// Acquisitions by verdict.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct AcquisitionCounts {
    /// Accepted within the far-off bound.
    pub correct: usize,
    /// Accepted beyond it.
    pub false_accepts: usize,
    /// Refused by the checks.
    pub rejected: usize,
}

impl AcquisitionCounts {
    /// The counts of `records`.
    pub fn of<'a>(records: impl IntoIterator<Item = &'a AcquisitionRecord>) -> Self {
        let mut c = Self::default();
        for r in records {
            match r.verdict {
                "correct" => c.correct += 1,
                "false-accept" => c.false_accepts += 1,
                "rejected" => c.rejected += 1,
                _ => {}
            }
        }
        c
    }
}

/// Scores `a`, computed on `frame`, against `truth` (`t_sensor_target` at
/// that frame's scan end) with the target's `symmetries`.
pub fn score(
    frame: u64,
    a: &AcquisitionResult,
    truth: Option<&Pose>,
    symmetries: &[Rotation3<f64>],
) -> AcquisitionRecord {
    let accepted = a.success == 1;
    let error = truth
        .zip(a.pose().ok())
        .map(|(t, p)| pose_error(&p, t, symmetries));
    let verdict = match (accepted, error) {
        (false, _) => "rejected",
        (true, None) => "unscored",
        (true, Some((ang, pos))) if far_off(ang, pos) => "false-accept",
        (true, Some(_)) => "correct",
    };
    AcquisitionRecord {
        frame,
        method: AcquisitionMethod::from_u8(a.method)
            .map_or("unknown", AcquisitionMethod::as_str)
            .to_owned(),
        accepted,
        f_conv_m2: a.f_conv_m2,
        time_ms: a.time_ms,
        ang_err_deg: error.map(|e| e.0),
        pos_err_m: error.map(|e| e.1),
        verdict,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn verdicts_follow_the_far_off_bound_and_the_symmetries() {
        let truth = Pose::new(Rotation3::identity(), Vector3::new(0.0, 0.0, 15.0));
        let mut a = AcquisitionResult::new();
        a.method = AcquisitionMethod::Cnn as u8;
        a.p_sensor_target = [0.0, 0.0, 15.1];
        assert_eq!(score(3, &a, Some(&truth), &[]).verdict, "rejected");
        a.success = 1;
        assert_eq!(score(3, &a, Some(&truth), &[]).verdict, "correct");
        assert_eq!(score(3, &a, None, &[]).verdict, "unscored");
        // Turned 120° about z: wrong, unless that turn is a symmetry.
        let turn = Rotation3::from_axis_angle(&Vector3::z_axis(), 120f64.to_radians());
        a.set_pose(&Pose::new(turn, Vector3::new(0.0, 0.0, 15.1)));
        let r = score(3, &a, Some(&truth), &[]);
        assert_eq!(r.verdict, "false-accept");
        assert!((r.ang_err_deg.expect("scored") - 120.0).abs() < 1e-6);
        let group = [Rotation3::identity(), turn, turn * turn];
        assert_eq!(score(3, &a, Some(&truth), &group).verdict, "correct");
        a.p_sensor_target = [0.0, 0.6, 15.0];
        assert_eq!(score(3, &a, Some(&truth), &group).verdict, "false-accept");
        let counts = AcquisitionCounts::of(&[score(3, &a, Some(&truth), &group)]);
        assert_eq!(counts.false_accepts, 1);
    }
}
