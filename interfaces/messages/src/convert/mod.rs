//! Conversions between the wire messages and the domain types: the one
//! place each message is turned into what a node works with.
//!
//! - here: arrays, quaternions, poses, 6x6 matrices;
//! - `pose_access`: `pose()` / `set_pose()` on every message that carries
//!   `t_sensor_target`;
//! - [`filter`]: `FilterState` ↔ the filter's `Prediction`, a `PoseEstimate`
//!   as a measurement, an `AcquisitionResult` as a starting pose.
//!
//! Quaternions travel in the order **w, x, y, z** (scalar first).

pub mod filter;
mod pose_access;

pub use filter::{
    Measurement, acquisition_pose, measurement_from_estimate, prediction_from_state,
    state_from_prediction,
};

use crate::error::MessageError;
use nalgebra::{Quaternion, Rotation3, SMatrix, UnitQuaternion, Vector3};
use spacepose_geometry::Pose;

/// Largest accepted deviation of a received quaternion's norm from 1.
pub const QUATERNION_NORM_TOLERANCE: f64 = 1e-3;

/// A rotation as a unit quaternion `[w, x, y, z]` (w ≥ 0).
pub fn quaternion_wxyz(rotation: &Rotation3<f64>) -> [f64; 4] {
    let q = UnitQuaternion::from_rotation_matrix(rotation);
    let s = if q.w < 0.0 { -1.0 } else { 1.0 };
    [s * q.w, s * q.i, s * q.j, s * q.k]
}

/// A rotation from a quaternion `[w, x, y, z]`; rejects non-finite values and
/// norms further than [`QUATERNION_NORM_TOLERANCE`] from 1, renormalises the rest.
pub fn rotation_from_wxyz(q: &[f64; 4]) -> Result<Rotation3<f64>, MessageError> {
    if !q.iter().all(|v| v.is_finite()) {
        return Err(MessageError::NonFinitePose);
    }
    let quaternion = Quaternion::new(q[0], q[1], q[2], q[3]);
    let norm = quaternion.norm();
    if (norm - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
        return Err(MessageError::InvalidQuaternion { norm });
    }
    Ok(UnitQuaternion::from_quaternion(quaternion).to_rotation_matrix())
}

/// A pose as wire arrays: (quaternion w, x, y, z; position m).
pub fn pose_to_wire(pose: &Pose) -> ([f64; 4], [f64; 3]) {
    (
        quaternion_wxyz(&pose.rotation),
        vector3_to_wire(&pose.translation),
    )
}

/// A pose from wire arrays (quaternion w, x, y, z; position m).
pub fn pose_from_wire(q: &[f64; 4], p: &[f64; 3]) -> Result<Pose, MessageError> {
    let rotation = rotation_from_wxyz(q)?;
    if !p.iter().all(|v| v.is_finite()) {
        return Err(MessageError::NonFinitePose);
    }
    Ok(Pose::new(rotation, vector3_from_wire(p)))
}

/// A 3-vector as an array.
pub fn vector3_to_wire(v: &Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// An array as a 3-vector.
pub fn vector3_from_wire(v: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

/// A square matrix as row-major arrays.
pub fn matrix_to_wire<const N: usize>(m: &SMatrix<f64, N, N>) -> [[f64; N]; N] {
    let mut out = [[0.0; N]; N];
    for (r, row) in out.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v = m[(r, c)];
        }
    }
    out
}

/// Row-major arrays as a square matrix.
pub fn matrix_from_wire<const N: usize>(m: &[[f64; N]; N]) -> SMatrix<f64, N, N> {
    SMatrix::from_fn(|r, c| m[r][c])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PoseEstimate;
    use approx::assert_relative_eq;
    use spacepose_geometry::so3;

    #[test]
    fn poses_round_trip_with_scalar_first_quaternions() {
        let pose = Pose::new(
            so3::exp(&Vector3::new(0.3, -1.2, 2.5)),
            Vector3::new(1.0, -2.0, 30.0),
        );
        let (q, p) = pose_to_wire(&pose);
        assert!(q[0] >= 0.0);
        let back = pose_from_wire(&q, &p).unwrap();
        let (angle, dist) = pose.error_to(&back);
        assert!(angle < 1e-12 && dist < 1e-12);
        // A rotation of 90° about z: w = cos 45°, z = sin 45° (scalar first).
        let rz = Rotation3::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2);
        let q = quaternion_wxyz(&rz);
        assert_relative_eq!(q[0], std::f64::consts::FRAC_1_SQRT_2, epsilon = 1e-12);
        assert_relative_eq!(q[3], std::f64::consts::FRAC_1_SQRT_2, epsilon = 1e-12);
    }

    #[test]
    fn bad_quaternions_and_positions_are_errors() {
        assert!(matches!(
            pose_from_wire(&[0.0; 4], &[0.0; 3]),
            Err(MessageError::InvalidQuaternion { .. })
        ));
        assert!(matches!(
            pose_from_wire(&[f64::NAN, 0.0, 0.0, 0.0], &[0.0; 3]),
            Err(MessageError::NonFinitePose)
        ));
        assert!(matches!(
            pose_from_wire(&[1.0, 0.0, 0.0, 0.0], &[0.0, f64::INFINITY, 0.0]),
            Err(MessageError::NonFinitePose)
        ));
    }

    #[test]
    fn messages_carry_poses_and_matrices() {
        let pose = Pose::new(
            so3::exp(&Vector3::new(-0.1, 0.2, 0.3)),
            Vector3::new(0.5, 0.6, 12.0),
        );
        let mut msg = PoseEstimate::new();
        msg.set_pose(&pose);
        let (angle, dist) = msg.pose().unwrap().error_to(&pose);
        assert!(angle < 1e-12 && dist < 1e-12);
        let m = nalgebra::Matrix6::from_fn(|r, c| (r * 6 + c) as f64);
        let wire = matrix_to_wire(&m);
        assert_eq!(wire[1][2], 8.0);
        assert_eq!(matrix_from_wire(&wire), m);
    }
}
