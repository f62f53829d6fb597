//! Rigid transforms `T = (R, p)` in SE(3), seen as SO(3) × R³ as in seed 000
//! §3.1, with the left "round-plus" of Eq. (5) and the point Jacobian of
//! Eq. (6).

use crate::so3;
use nalgebra::{Matrix3, Matrix3x6, Rotation3, Vector3, Vector6};
use serde::{Deserialize, Serialize};

/// A rigid transform `x_a = R x_b + p`. Name instances after the frames they
/// link: `t_sensor_target` maps target-body coordinates into the sensor frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Rotation `R`.
    pub rotation: Rotation3<f64>,
    /// Translation `p` (m).
    pub translation: Vector3<f64>,
}

impl Default for Pose {
    fn default() -> Self {
        Self::identity()
    }
}

impl Pose {
    /// The identity transform.
    pub fn identity() -> Self {
        Self {
            rotation: Rotation3::identity(),
            translation: Vector3::zeros(),
        }
    }

    /// A transform from its rotation and translation.
    pub fn new(rotation: Rotation3<f64>, translation: Vector3<f64>) -> Self {
        Self {
            rotation,
            translation,
        }
    }

    /// `T(z) = R z + p`.
    #[inline]
    pub fn transform(&self, z: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * z + self.translation
    }

    /// `T⁻¹`.
    pub fn inverse(&self) -> Self {
        let r_inv = self.rotation.inverse();
        Self {
            rotation: r_inv,
            translation: -(r_inv * self.translation),
        }
    }

    /// `self ∘ other`: apply `other` first, then `self`.
    pub fn compose(&self, other: &Pose) -> Self {
        Self {
            rotation: self.rotation * other.rotation,
            translation: self.rotation * other.translation + self.translation,
        }
    }

    /// The left ⊕ of seed 000 Eq. (5):
    /// `δ ⊕ T = (Exp(δ₁:₃) R, δ₄:₆ + p)`.
    pub fn oplus(&self, delta: &Vector6<f64>) -> Self {
        let dr = Vector3::new(delta[0], delta[1], delta[2]);
        let dp = Vector3::new(delta[3], delta[4], delta[5]);
        let rotation = so3::exp(&dr) * self.rotation;
        // Re-orthonormalise so thousands of increments never drift off SO(3).
        let rotation = Rotation3::from_matrix_eps(rotation.matrix(), 1e-12, 4, rotation);
        Self {
            rotation,
            translation: self.translation + dp,
        }
    }

    /// The inverse of [`Pose::oplus`]: the `δ` with `δ ⊕ other = self`.
    pub fn ominus(&self, other: &Pose) -> Vector6<f64> {
        let dr = so3::log(&(self.rotation * other.rotation.inverse()));
        let dp = self.translation - other.translation;
        Vector6::new(dr.x, dr.y, dr.z, dp.x, dp.y, dp.z)
    }

    /// The left Jacobian of `T(z)` with respect to `T` (seed 000 Eq. 6):
    /// `J = [-(R z)^×  I₃]`.
    #[inline]
    pub fn point_jacobian(&self, z: &Vector3<f64>) -> Matrix3x6<f64> {
        let rz = self.rotation * z;
        let mut j = Matrix3x6::zeros();
        j.fixed_view_mut::<3, 3>(0, 0).copy_from(&(-so3::hat(&rz)));
        j.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&Matrix3::identity());
        j
    }

    /// True when every entry is finite.
    pub fn is_finite(&self) -> bool {
        self.rotation.matrix().iter().all(|v| v.is_finite())
            && self.translation.iter().all(|v| v.is_finite())
    }

    /// Rotation angle between two poses (rad) and translation distance (m).
    pub fn error_to(&self, other: &Pose) -> (f64, f64) {
        (
            so3::distance(&self.rotation, &other.rotation),
            (self.translation - other.translation).norm(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_pose() -> Pose {
        Pose::new(
            so3::exp(&Vector3::new(0.4, -1.1, 0.7)),
            Vector3::new(1.0, -2.0, 9.0),
        )
    }

    #[test]
    fn inverse_and_compose_cancel() {
        let t = sample_pose();
        let id = t.compose(&t.inverse());
        assert!(id.rotation.angle() < 1e-12);
        assert!(id.translation.norm() < 1e-12);
    }

    #[test]
    fn oplus_ominus_round_trip() {
        let t = sample_pose();
        let d = Vector6::new(0.01, -0.2, 0.3, 0.5, -0.1, 0.02);
        let back = t.oplus(&d).ominus(&t);
        assert!((back - d).norm() < 1e-12);
    }

    #[test]
    fn point_jacobian_matches_finite_differences() {
        // J_i = lim ((δ ⊕ T)(z) - T(z)) / δ (Eq. 6), central differences.
        let t = sample_pose();
        let z = Vector3::new(0.3, -1.2, 2.0);
        let h = 1e-6;
        let mut fd = Matrix3x6::zeros();
        for j in 0..6 {
            let mut d = Vector6::zeros();
            d[j] = h;
            let col = (t.oplus(&d).transform(&z) - t.oplus(&(-d)).transform(&z)) / (2.0 * h);
            fd.set_column(j, &col);
        }
        let an = t.point_jacobian(&z);
        let rel = (an - fd).norm() / fd.norm();
        assert!(rel < 1e-6, "relative error {rel}");
    }
}
