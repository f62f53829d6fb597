//! From the registration's information matrix to the measurement covariance
//! the filter expects.
//!
//! The registration estimates `t_target_sensor` (it moves the scan into the
//! model frame, seed 000 Eq. 3) and its information `Λ` refers to a left
//! perturbation `δ` of that pose (Eq. 5). The filter fuses `t_sensor_target`
//! with the same kind of left perturbation `ξ` on the inverse pose. With
//! `T_ts = (R_ts, p_ts)` and `R_st = R_tsᵀ`, to first order
//! `ξ_rot = -R_st δ_rot` and `ξ_pos = -R_st δ_pos - R_st p_ts^× δ_rot`, i.e.
//! `ξ = A δ` with `A = [[-R_st, 0], [-R_st p_ts^×, -R_st]]`, and
//! `Σ_ξ = A Λ⁻¹ Aᵀ`.

use nalgebra::{Matrix3, Matrix6};
use spacepose_geometry::{Pose, so3};

/// The Jacobian `A = ∂ξ/∂δ` of the inversion `t_sensor_target = t_target_sensor⁻¹`
/// for left perturbations on both sides.
pub fn inversion_jacobian(t_target_sensor: &Pose) -> Matrix6<f64> {
    let r_st = t_target_sensor.rotation.inverse().into_inner();
    let mut a = Matrix6::zeros();
    a.fixed_view_mut::<3, 3>(0, 0).copy_from(&(-r_st));
    a.fixed_view_mut::<3, 3>(3, 0)
        .copy_from(&(-r_st * so3::hat(&t_target_sensor.translation)));
    a.fixed_view_mut::<3, 3>(3, 3).copy_from(&(-r_st));
    a
}

/// The covariance of `t_sensor_target` from the information of
/// `t_target_sensor`; `None` when `Λ` is not positive definite.
pub fn covariance_sensor_target(
    t_target_sensor: &Pose,
    information: &Matrix6<f64>,
) -> Option<Matrix6<f64>> {
    if !information.iter().all(|v| v.is_finite()) {
        return None;
    }
    let sym = (information + information.transpose()) * 0.5;
    let cov_delta = sym.cholesky()?.inverse();
    let a = inversion_jacobian(t_target_sensor);
    let cov = a * cov_delta * a.transpose();
    Some((cov + cov.transpose()) * 0.5)
}

/// Square root of the largest eigenvalue of a 3×3 covariance block: the
/// worst-axis standard deviation.
pub fn worst_sigma(block: &Matrix3<f64>) -> f64 {
    block.symmetric_eigenvalues().max().max(0.0).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector3, Vector6};

    #[test]
    fn inversion_jacobian_matches_finite_differences() {
        let t_ts = Pose::new(
            so3::exp(&Vector3::new(0.3, -0.7, 1.1)),
            Vector3::new(0.5, -1.0, 8.0),
        );
        let t_st = t_ts.inverse();
        let a = inversion_jacobian(&t_ts);
        let h = 1e-6;
        let mut fd = Matrix6::zeros();
        for j in 0..6 {
            let mut d = Vector6::zeros();
            d[j] = h;
            let plus = t_ts.oplus(&d).inverse().ominus(&t_st);
            let minus = t_ts.oplus(&(-d)).inverse().ominus(&t_st);
            fd.set_column(j, &((plus - minus) / (2.0 * h)));
        }
        let rel = (a - fd).norm() / fd.norm();
        assert!(rel < 1e-6, "relative error {rel}");
    }

    #[test]
    fn covariance_needs_a_positive_definite_information() {
        let t = Pose::identity();
        let info = Matrix6::identity() * 4.0;
        let cov = covariance_sensor_target(&t, &info).unwrap();
        assert!((cov - Matrix6::identity() * 0.25).norm() < 1e-12);
        assert!(covariance_sensor_target(&t, &Matrix6::zeros()).is_none());
        let mut nan = info;
        nan[(0, 0)] = f64::NAN;
        assert!(covariance_sensor_target(&t, &nan).is_none());
    }
}
