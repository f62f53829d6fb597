//! The eval's one far-off bound: frames, acquisitions and tables use it.

/// A frame whose error exceeds these has lost the target in truth, whatever
/// the tracker reports.
pub const DIVERGED_DEG: f64 = 10.0;
/// See [`DIVERGED_DEG`] (m).
pub const DIVERGED_M: f64 = 0.5;

use nalgebra::{Rotation3, Vector3};
use spacepose_geometry::{Pose, so3};

/// The eval's one error of an estimate against the truth: the attitude
/// error (deg; d_sym of seed 004 Eq. 14 over `symmetries`, d when empty)
/// and the distance between the centres of mass (m).
pub fn pose_error(estimate: &Pose, truth: &Pose, symmetries: &[Rotation3<f64>]) -> (f64, f64) {
    let ang = so3::distance_sym(&estimate.rotation, &truth.rotation, symmetries);
    (
        ang.to_degrees(),
        (estimate.translation - truth.translation).norm(),
    )
}

/// The attitude error `Log(Qᵀ R)` of `estimate` (R) against the symmetric
/// variant `Q = truth S_k` nearest it (rad, target frame).
pub fn error_rotvec(estimate: &Pose, truth: &Pose, symmetries: &[Rotation3<f64>]) -> Vector3<f64> {
    let identity = [Rotation3::identity()];
    let group = if symmetries.is_empty() {
        &identity[..]
    } else {
        symmetries
    };
    group
        .iter()
        .map(|s| so3::log(&((truth.rotation * s).transpose() * estimate.rotation)))
        .min_by(|a, b| a.norm().total_cmp(&b.norm()))
        .unwrap_or_else(Vector3::zeros)
}

/// More than [`DIVERGED_DEG`] or [`DIVERGED_M`] off; NaN errors count.
pub fn far_off(ang_deg: f64, pos_m: f64) -> bool {
    !(ang_deg <= DIVERGED_DEG && pos_m <= DIVERGED_M)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_error_rotation_vector_is_in_the_target_frame_against_the_nearest_symmetric_truth() {
        let rx = |deg: f64| Rotation3::from_axis_angle(&Vector3::x_axis(), deg.to_radians());
        let truth = Pose::new(
            Rotation3::from_euler_angles(0.3, -0.4, 1.1),
            Vector3::new(0.0, 0.0, 15.0),
        );
        let twin = Pose::new(truth.rotation * rx(-60.0), truth.translation);
        let v = error_rotvec(&twin, &truth, &[]);
        assert!(
            (v - Vector3::new(-60f64.to_radians(), 0.0, 0.0)).norm() < 1e-9,
            "{v}"
        );
        // With a ±120° group about x, 100° about x is 20° from a variant.
        let group = [Rotation3::identity(), rx(120.0), rx(-120.0)];
        let near = Pose::new(truth.rotation * rx(100.0), truth.translation);
        let v = error_rotvec(&near, &truth, &group);
        assert!(
            (v - Vector3::new(-20f64.to_radians(), 0.0, 0.0)).norm() < 1e-9,
            "{v}"
        );
        let (deg, _) = pose_error(&near, &truth, &group);
        assert!((v.norm().to_degrees() - deg).abs() < 1e-9);
    }
}
