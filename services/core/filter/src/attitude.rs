//! Invariant EKF on the relative attitude and angular velocity
//! (seed 000 §3.2, Eq. 9 and 11; Barrau & Bonnabel, seed 000 refs 44-45).
//!
//! # State, model and error
//! `R` = attitude of the target in the sensor frame (`r_sensor_target`),
//! `ω` = angular velocity of the target in the target frame. Constant angular
//! velocity model (Eq. 9), with process noise:
//! `R_{k+1} = R_k Exp(ω_k Δt)`, `ω_{k+1} = ω_k`.
//!
//! The estimation error follows the left ⊕ of Eq. (5), which is also the one
//! of the update of Eq. (11):
//! `R = Exp(ξ_R) R̂`, `ω = ω̂ + ξ_ω`, error state `ξ = [ξ_R; ξ_ω]` with
//! covariance `P`. `Exp(ξ_R) = R R̂ᵀ` is the right-invariant error of
//! Barrau & Bonnabel (unchanged when `R` and `R̂` are both right-multiplied
//! by the same rotation).
//!
//! # Propagation (derivation)
//! With `J_r(x) = D_exp(-x)` the right Jacobian of SO(3),
//! `Exp(x + δ) = Exp(x) Exp(J_r(x) δ) + O(δ²)`, and the adjoint identity
//! `R Exp(a) Rᵀ = Exp(R a)`:
//! ```text
//! R_{k+1} = Exp(ξ_R) R̂ Exp((ω̂ + ξ_ω) Δt)
//!         = Exp(ξ_R) R̂ Exp(ω̂Δt) Exp(J_r(ω̂Δt) ξ_ω Δt)
//!         = Exp(ξ_R) Exp(R̂⁻ J_r(ω̂Δt) ξ_ω Δt) R̂⁻        with R̂⁻ = R̂ Exp(ω̂Δt)
//!         = Exp(ξ_R + R̂⁻ J_r(ω̂Δt) Δt ξ_ω) R̂⁻ + O(|ξ|²)
//! ```
//! so `ξ⁻ = F ξ` with
//! `F = [[I, R̂⁻ J_r(ω̂Δt) Δt], [0, I]]`.
//! The same block follows from the continuous error dynamics
//! `dξ_R/dt = R̂(t) ξ_ω`: `∫₀^Δt R̂ Exp(ω̂ s) ds = R̂ J_l(ω̂Δt) Δt =
//! R̂⁻ J_r(ω̂Δt) Δt` because `J_l(x) = Exp(x) J_r(x)`.
//! The attitude block of `F` is the identity whatever the estimate: this is
//! the invariance property the IEKF is built on. The coupling block depends on
//! the estimate (`(R, ω)` with `ω` in the body frame and an additive `ω`
//! error is not group-affine), so the `ω` part behaves like an ordinary EKF.
//! The test `f_matches_numerical_linearisation` checks `F` by finite
//! differences.
//!
//! # Process noise
//! Continuous white noise on the attitude (left, density `q_rot`, rad²/s)
//! and a random walk on `ω` (density `q_w`, rad²/s³). With `B = R̂⁻ J_r(ω̂Δt)`
//! held constant over the step:
//! `Q = [[q_rot Δt I + q_w Δt³/3 B Bᵀ, q_w Δt²/2 B], [q_w Δt²/2 Bᵀ, q_w Δt I]]`
//! (positive semi-definite by construction; exact as `ω̂Δt → 0`).
//!
//! # Measurement and update (Eq. 11)
//! The registration measures `R̄ = Exp(n) R`, `n ~ N(0, N)` (left
//! perturbation, as the registration's covariance). The innovation
//! `y = Log(R̄ R̂⁻ᵀ) = Log(Exp(n) Exp(ξ_R)) ≈ ξ_R + n` gives `H = [I 0]`,
//! again independent of the estimate. With the Kalman gain `K` (6x3):
//! `δ = K y`, `(R, ω) ← (Exp(δ₁:₃) R̂⁻, ω̂⁻ + δ₄:₆)` (Eq. 11), Joseph-form `P`.
//! Finally the covariance is moved to the new estimate: with `ξ = δ_R + e`,
//! `Exp(ξ) Exp(-δ_R) ≈ Exp(J_l(δ_R) e)`, so `P ← G P Gᵀ`,
//! `G = diag(J_l(δ_R), I)` (a second-order correction; `J_l = D_exp`).

use crate::error::FilterError;
use crate::kalman::{Innovation, checked_covariance3, symmetrize6, update_first_block};
use crate::position::{check_covariance6, check_step};
use nalgebra::{Matrix3, Matrix6, Rotation3, UnitQuaternion, Vector3};
use spacepose_geometry::so3;

/// The right Jacobian of SO(3), `J_r(x) = D_exp(-x)`:
/// `Exp(x + δ) ≈ Exp(x) Exp(J_r(x) δ)`.
pub fn right_jacobian(x: &Vector3<f64>) -> Matrix3<f64> {
    so3::d_exp(&(-x))
}

/// Attitude/angular-velocity estimate of the target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeFilter {
    /// Attitude of the target in the sensor frame.
    pub r_sensor_target: Rotation3<f64>,
    /// Angular velocity of the target, in the target frame (rad/s).
    pub w_target: Vector3<f64>,
    /// Covariance of the error `[ξ_R; ξ_ω]` (rad², rad²/s²).
    pub covariance: Matrix6<f64>,
}

impl AttitudeFilter {
    /// A filter state. Fails on non-finite input or a covariance that is not
    /// symmetric positive definite.
    pub fn new(
        r_sensor_target: Rotation3<f64>,
        w_target: Vector3<f64>,
        covariance: Matrix6<f64>,
    ) -> Result<Self, FilterError> {
        let finite = r_sensor_target
            .matrix()
            .iter()
            .chain(w_target.iter())
            .all(|v| v.is_finite());
        if !finite {
            return Err(FilterError::NonFinite {
                what: "attitude filter state",
            });
        }
        check_covariance6(&covariance, "attitude filter covariance")?;
        Ok(Self {
            r_sensor_target: renormalize(&r_sensor_target),
            w_target,
            covariance: symmetrize6(&covariance),
        })
    }

    /// The angular velocity in the sensor frame, `R ω` (rad/s).
    pub fn w_sensor(&self) -> Vector3<f64> {
        self.r_sensor_target * self.w_target
    }

    /// The propagated mean `R̂ Exp(ω̂ Δt)` (Eq. 9).
    pub fn predicted_rotation(&self, dt: f64) -> Rotation3<f64> {
        renormalize(&(self.r_sensor_target * so3::exp(&(self.w_target * dt))))
    }

    /// The block `B = R̂⁻ J_r(ω̂Δt)`, so that `F = [[I, B Δt], [0, I]]`.
    fn coupling(&self, dt: f64) -> Matrix3<f64> {
        self.predicted_rotation(dt).matrix() * right_jacobian(&(self.w_target * dt))
    }

    /// The error-state transition `F = [[I, R̂⁻ J_r(ω̂Δt) Δt], [0, I]]`.
    pub fn transition_matrix(&self, dt: f64) -> Matrix6<f64> {
        let mut f = Matrix6::identity();
        f.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(self.coupling(dt) * dt));
        f
    }

    /// The process noise `Q` accumulated over `Δt` (see the module docs).
    pub fn process_noise(&self, dt: f64, q_rot: f64, q_w: f64) -> Matrix6<f64> {
        let b = self.coupling(dt);
        let mut q = Matrix6::zeros();
        let rr = Matrix3::identity() * (q_rot * dt) + b * b.transpose() * (q_w * dt.powi(3) / 3.0);
        q.fixed_view_mut::<3, 3>(0, 0).copy_from(&rr);
        q.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(b * (q_w * dt * dt / 2.0)));
        q.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&(b.transpose() * (q_w * dt * dt / 2.0)));
        q.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&(Matrix3::identity() * (q_w * dt)));
        symmetrize6(&q)
    }

    /// The prediction `Δt ≥ 0` seconds ahead (Eq. 9); `self` is unchanged.
    pub fn predict(&self, dt: f64, q_rot: f64, q_w: f64) -> Result<Self, FilterError> {
        check_step(dt, q_rot)?;
        check_step(dt, q_w)?;
        let f = self.transition_matrix(dt);
        let p = f * self.covariance * f.transpose() + self.process_noise(dt, q_rot, q_w);
        Ok(Self {
            r_sensor_target: self.predicted_rotation(dt),
            w_target: self.w_target,
            covariance: symmetrize6(&p),
        })
    }

    /// The innovation `y = Log(R̄ R̂ᵀ)` of a measured attitude with noise `N`
    /// (left perturbation, rad²).
    pub fn innovation(
        &self,
        r_measured: &Rotation3<f64>,
        n: &Matrix3<f64>,
    ) -> Result<Innovation, FilterError> {
        if !r_measured.matrix().iter().all(|v| v.is_finite()) {
            return Err(FilterError::NonFinite {
                what: "measured attitude",
            });
        }
        let n = checked_covariance3(n, "attitude measurement covariance")?;
        let y = so3::log(&(r_measured * self.r_sensor_target.inverse()));
        Ok(Innovation::new(y, &self.covariance, &n))
    }

    /// Fuses a measured attitude into this (predicted) state (Eq. 11) and
    /// returns the innovation it used.
    pub fn update(
        &mut self,
        r_measured: &Rotation3<f64>,
        n: &Matrix3<f64>,
    ) -> Result<Innovation, FilterError> {
        let innovation = self.innovation(r_measured, n)?;
        let step = update_first_block(&self.covariance, &innovation, n)?;
        let d_rot: Vector3<f64> = step.correction.fixed_rows::<3>(0).into_owned();
        // Eq. (11): (R, ω) ← (K y) ⊕ (R⁻, ω⁻), ⊕ = (Exp(δ₁:₃) R, ω + δ₄:₆).
        self.r_sensor_target = renormalize(&(so3::exp(&d_rot) * self.r_sensor_target));
        self.w_target += step.correction.fixed_rows::<3>(3);
        // Move the covariance to the error around the new estimate.
        let mut g = Matrix6::identity();
        g.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&so3::d_exp(&d_rot));
        self.covariance = symmetrize6(&(g * step.covariance * g.transpose()));
        Ok(innovation)
    }
}

/// Projects a nearly orthonormal matrix back onto SO(3) (through the unit
/// quaternion), so thousands of steps never drift.
fn renormalize(r: &Rotation3<f64>) -> Rotation3<f64> {
    // `from_rotation_matrix` does not normalise; `new_normalize` does.
    let q = UnitQuaternion::from_rotation_matrix(r);
    UnitQuaternion::new_normalize(*q.quaternion()).to_rotation_matrix()
}

#[cfg(test)]
#[path = "attitude_tests.rs"]
mod tests;
