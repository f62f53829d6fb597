//! A Gaussian prior on how far the target's origin moves in the sensor
//! frame over a continuous-time scan: the translational companion of
//! [`super::RatePrior`] (not in seed 000).
//!
//! CT-NDT interpolates the target origin `p = -Rᵀ t` (in the sensor frame,
//! for `t_target_sensor = (R, t)`) linearly over the scan, the
//! constant-velocity motion of Eq. (8). This prior states the displacement
//! `p^e - p^s` the filter predicts, `v Δt`, with the information of its
//! velocity estimate over the scan.

use crate::error::RegistrationError;
use nalgebra::{Matrix3, Vector3};
use spacepose_geometry::{Pose, so3};

/// A Gaussian prior on the displacement `p^e - p^s` of the target origin in
/// the sensor frame over a scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DisplacementPrior {
    /// The expected displacement (m, sensor frame), e.g. the filter's
    /// velocity times the scan duration.
    pub displacement_m: Vector3<f64>,
    /// Information of the displacement error (m⁻², sensor frame), symmetric
    /// positive semi-definite, in the units of the NDT information (Eq. 7).
    pub information: Matrix3<f64>,
}

/// The residual of a [`DisplacementPrior`] and its derivatives with respect
/// to the left perturbations `[rot; trans]` of the start and end poses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct DisplacementResidual {
    /// `e = p^e - p^s - d₀`.
    pub e: Vector3<f64>,
    /// `∂e/∂δ^s` as (rotation, translation) blocks.
    pub j_start: (Matrix3<f64>, Matrix3<f64>),
    /// `∂e/∂δ^e` as (rotation, translation) blocks.
    pub j_end: (Matrix3<f64>, Matrix3<f64>),
}

/// `p = -Rᵀ t` and its derivatives: with `R ← Exp(a) R`, `t ← t + b`,
/// `p ← -Rᵀ Exp(-a) (t + b) ≈ p - Rᵀ [t]× a - Rᵀ b`.
fn origin(pose: &Pose) -> (Vector3<f64>, Matrix3<f64>, Matrix3<f64>) {
    let rt = pose.rotation.matrix().transpose();
    let p = -(rt * pose.translation);
    (p, -(rt * so3::hat(&pose.translation)), -rt)
}

impl DisplacementPrior {
    /// Rejects a non-finite displacement or information, or a negative
    /// diagonal.
    pub fn validate(&self) -> Result<(), RegistrationError> {
        let ok = self.displacement_m.iter().all(|v| v.is_finite())
            && self.information.iter().all(|v| v.is_finite())
            && self.information.diagonal().iter().all(|&d| d >= 0.0);
        if ok {
            Ok(())
        } else {
            Err(RegistrationError::param(
                "displacement_prior",
                "need a finite displacement and information with a non-negative diagonal",
            ))
        }
    }

    /// The residual at `t_target_sensor` poses `start` and `end`.
    pub(crate) fn residual(&self, start: &Pose, end: &Pose) -> DisplacementResidual {
        let (p_s, a_s, b_s) = origin(start);
        let (p_e, a_e, b_e) = origin(end);
        DisplacementResidual {
            e: p_e - p_s - self.displacement_m,
            j_start: (-a_s, -b_s),
            j_end: (a_e, b_e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector6;

    fn pose(r: [f64; 3], t: [f64; 3]) -> Pose {
        Pose::new(so3::exp(&Vector3::from(r)), Vector3::from(t))
    }

    /// The blocks agree with central finite differences of the residual.
    #[test]
    fn jacobians_agree_with_finite_differences() {
        let prior = DisplacementPrior {
            displacement_m: Vector3::new(0.01, -0.02, 0.005),
            information: Matrix3::identity(),
        };
        let (s, e) = (
            pose([0.4, -0.7, 1.1], [1.0, 2.0, -9.0]),
            pose([0.5, -0.8, 1.0], [1.1, 2.0, -8.9]),
        );
        let r = prior.residual(&s, &e);
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for j in 0..6 {
            let mut d = Vector6::zeros();
            d[j] = h;
            let at_s = |d: &Vector6<f64>| prior.residual(&s.oplus(d), &e).e;
            let at_e = |d: &Vector6<f64>| prior.residual(&s, &e.oplus(d)).e;
            let fd_s = (at_s(&d) - at_s(&-d)) / (2.0 * h);
            let fd_e = (at_e(&d) - at_e(&-d)) / (2.0 * h);
            let col = |b: &(Matrix3<f64>, Matrix3<f64>)| {
                if j < 3 {
                    b.0.column(j).into_owned()
                } else {
                    b.1.column(j - 3).into_owned()
                }
            };
            worst = worst.max((fd_s - col(&r.j_start)).norm());
            worst = worst.max((fd_e - col(&r.j_end)).norm());
        }
        assert!(worst < 1e-7, "worst absolute error {worst}");
    }

    #[test]
    fn non_finite_prior_is_rejected() {
        let mut prior = DisplacementPrior {
            displacement_m: Vector3::zeros(),
            information: Matrix3::identity(),
        };
        assert!(prior.validate().is_ok());
        prior.displacement_m.y = f64::INFINITY;
        assert!(prior.validate().is_err());
    }
}
