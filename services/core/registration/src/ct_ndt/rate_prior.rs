//! A Gaussian prior on the rotation a continuous-time scan turns through
//! (not in seed 000; measured in `docs/design/ct-ndt-motion-prior.md`).
//!
//! The free-start CT-NDT ([`super::register_ct_ndt_free_start`]) fits the
//! start and end poses of a scan, i.e. a pose and a motion. A 1 Hz scan at
//! a few degrees per second holds little information about the motion
//! within it, so the end pose, an extrapolation of the motion past the
//! middle of the scan, wanders most. The filter knows the motion from many
//! scans: this prior states the turn `R^e (R^s)ᵀ` it predicts, with the
//! information of its angular-velocity estimate over the scan. It leaves the
//! pose itself to the points, unlike a prior on the end pose (tried, and
//! dropped: the filter heard back its own prediction and lost the tumble).
//!
//! With an infinite information the turn is the predicted one and CT-NDT
//! fits one pose to the cloud compensated by the predicted motion, the
//! `deblur` of seed 000 §3.2; with none it is the free-start CT-NDT.

use crate::error::RegistrationError;
use nalgebra::{Matrix3, Rotation3, Vector3};
use spacepose_geometry::so3;

/// A Gaussian prior on the turn `Q = R^e (R^s)ᵀ` of `t_target_sensor`'s
/// rotation over a scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RatePrior {
    /// The expected turn `Q₀` (e.g. the filter's prediction:
    /// `Exp(-ω Δt)` for a target angular velocity `ω` in the target frame).
    pub turn: Rotation3<f64>,
    /// Information of `e = Log(Q Q₀ᵀ)` (rad⁻², target frame), symmetric
    /// positive semi-definite, in the units of the NDT information (Eq. 7).
    pub information: Matrix3<f64>,
}

/// The residual `e` of a [`RatePrior`] and its derivatives with respect to
/// the left rotation perturbations `a_s`, `a_e` of the start and end poses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RateResidual {
    /// `e = Log(R^e (R^s)ᵀ Q₀ᵀ)`.
    pub e: Vector3<f64>,
    /// `∂e/∂a_s = -J_l⁻¹(e) Q`.
    pub j_start: Matrix3<f64>,
    /// `∂e/∂a_e = J_l⁻¹(e)`.
    pub j_end: Matrix3<f64>,
}

impl RatePrior {
    /// Rejects a non-finite turn or information, or a negative diagonal.
    pub fn validate(&self) -> Result<(), RegistrationError> {
        let ok = self.turn.matrix().iter().all(|v| v.is_finite())
            && self.information.iter().all(|v| v.is_finite())
            && self.information.diagonal().iter().all(|&d| d >= 0.0);
        if ok {
            Ok(())
        } else {
            Err(RegistrationError::param(
                "rate_prior",
                "need a finite turn and information with a non-negative diagonal",
            ))
        }
    }

    /// The residual at start and end rotations `r_s`, `r_e`. With
    /// `R = Exp(a) R̄` at both ends, `R^e (R^s)ᵀ = Exp(a_e) Q̄ Exp(-a_s)
    /// = Exp(a_e) Exp(-Q̄ a_s) Q̄`, so to first order
    /// `e = Log(Exp(a_e - Q̄ a_s) Q̄ Q₀ᵀ)` and `D_log` gives the blocks.
    pub(crate) fn residual(&self, r_s: &Rotation3<f64>, r_e: &Rotation3<f64>) -> RateResidual {
        let q = r_e * r_s.inverse();
        let e = so3::log(&(q * self.turn.inverse()));
        let j_end = so3::d_exp_inv(&e);
        RateResidual {
            e,
            j_start: -(j_end * q.matrix()),
            j_end,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rotation(x: f64, y: f64, z: f64) -> Rotation3<f64> {
        so3::exp(&Vector3::new(x, y, z))
    }

    /// The blocks agree with central finite differences of the residual.
    #[test]
    fn jacobians_agree_with_finite_differences() {
        let prior = RatePrior {
            turn: rotation(0.02, -0.1, 0.05),
            information: Matrix3::identity(),
        };
        let (r_s, r_e) = (rotation(0.4, -0.7, 1.1), rotation(0.5, -0.9, 1.0));
        let r = prior.residual(&r_s, &r_e);
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for j in 0..3 {
            let mut d = Vector3::zeros();
            d[j] = h;
            let at_start = |d: &Vector3<f64>| prior.residual(&(so3::exp(d) * r_s), &r_e).e;
            let at_end = |d: &Vector3<f64>| prior.residual(&r_s, &(so3::exp(d) * r_e)).e;
            let fd_s = (at_start(&d) - at_start(&-d)) / (2.0 * h);
            let fd_e = (at_end(&d) - at_end(&-d)) / (2.0 * h);
            worst = worst.max((fd_s - r.j_start.column(j)).norm());
            worst = worst.max((fd_e - r.j_end.column(j)).norm());
        }
        assert!(worst < 1e-7, "worst absolute error {worst}");
    }

    /// The residual is zero exactly when the poses turn by the prior's turn.
    #[test]
    fn residual_vanishes_on_the_prior_turn() {
        let turn = rotation(0.0, -0.05, 0.01);
        let prior = RatePrior {
            turn,
            information: Matrix3::identity(),
        };
        let r_s = rotation(0.3, 0.2, -0.4);
        assert!(prior.residual(&r_s, &(turn * r_s)).e.norm() < 1e-12);
        let off = prior.residual(&r_s, &(rotation(0.0, 0.01, 0.0) * turn * r_s));
        assert!((off.e.norm() - 0.01).abs() < 1e-9);
    }

    #[test]
    fn non_finite_prior_is_rejected() {
        let mut prior = RatePrior {
            turn: Rotation3::identity(),
            information: Matrix3::identity(),
        };
        assert!(prior.validate().is_ok());
        prior.information[(1, 1)] = f64::NAN;
        assert!(prior.validate().is_err());
        prior.information = -Matrix3::identity();
        assert!(prior.validate().is_err());
    }
}
