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
use spacepose_registration::Registration;

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

/// The information the filter's measurement covariance comes from (see
/// `TrackerConfig::geometric_sigma_m`): the registration's geometric
/// information over `σ²`, lightly regularised, when `geometric_sigma_m > 0`
/// and the registration computed it; NDT's own information otherwise.
pub fn measurement_information(r: &Registration, geometric_sigma_m: f64) -> Matrix6<f64> {
    match r.geometric_information {
        Some(h) if geometric_sigma_m > 0.0 => {
            let info = h / (geometric_sigma_m * geometric_sigma_m);
            // A direction the surface does not constrain gets a variance
            // 1e9 times the best one's instead of an infinite one.
            let floor = 1e-9 * info.diagonal().max().max(f64::MIN_POSITIVE);
            info + Matrix6::identity() * floor
        }
        _ => r.information,
    }
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

    fn registration(geometric: Option<Matrix6<f64>>) -> Registration {
        Registration {
            t_target_sensor: Pose::identity(),
            converged: true,
            iterations: 3,
            cost: spacepose_registration::Cost {
                total: 1.0,
                mean: 0.01,
            },
            inliers: 100,
            valid_points: 100,
            skipped_non_finite: 0,
            mean_squared_distance_m2: 1e-4,
            f_conv_m2: None,
            information: Matrix6::identity() * 7.0,
            last_increment: spacepose_registration::Increment::default(),
            degenerate_directions: 1,
            weakest_lever_arm_m: 0.0,
            held_translations: 0,
            weakest_translation_cosine: 0.5,
            geometric_information: geometric,
        }
    }

    #[test]
    fn an_unconstrained_rotation_is_hardly_measured() {
        // Geometric information with nothing about the rotation about x.
        let mut h = Matrix6::identity() * 400.0;
        h[(0, 0)] = 0.0;
        let r = registration(Some(h));
        let info = measurement_information(&r, 0.02);
        let cov = covariance_sensor_target(&r.t_target_sensor, &info).unwrap();
        // σ = 2 cm over 400 points-worth: 1e-3 rad on the constrained axes…
        assert!((cov[(1, 1)].sqrt() - 1e-3).abs() < 1e-6, "{}", cov[(1, 1)]);
        // …and a variance 1e9 times larger about x.
        assert!(cov[(0, 0)] > 1e8 * cov[(1, 1)], "{}", cov[(0, 0)]);
        // Off, or without geometric information: NDT's information.
        assert_eq!(measurement_information(&r, 0.0), r.information);
        assert_eq!(
            measurement_information(&registration(None), 0.02),
            Matrix6::identity() * 7.0
        );
    }
}
