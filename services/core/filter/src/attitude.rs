//! Invariant EKF on the relative attitude, the target's angular velocity and
//! the sensor frame's own angular velocity (seed 000 §3.2, Eq. 9 and 11;
//! Barrau & Bonnabel, seed 000 refs 44-45; the third state is a departure,
//! `docs/design/sensor-frame-rate.md`).
//!
//! # State, model and error
//! `R` = attitude of the target in the sensor frame (`r_sensor_target`),
//! `ω` = angular velocity of the target with respect to inertial space, in
//! the target frame (`w_inertial_target`), `Ω` = angular velocity of the
//! sensor frame with respect to inertial space, in the sensor frame
//! (`w_inertial_sensor`: the chaser turning to keep the target in view).
//! Both rates are constant, with process noise:
//! `R_{k+1} = Exp(-Ω_k Δt) R_k Exp(ω_k Δt)`, `ω_{k+1} = ω_k`,
//! `Ω_{k+1} = Ω_k`. With `Ω = 0` this is Eq. (9), where the relative rate
//! is constant in the target frame; but a chaser that flies around a
//! tumbling target turns at about 1°/s, and that turn, fixed in the sensor
//! frame, changes the relative rate in the target frame as the target
//! turns: over 5 frames of the tumbling scenario a constant relative rate
//! extrapolates 2.0° wrong on average, the two rates 0.3°.
//!
//! The estimation error follows the left ⊕ of Eq. (5), which is also the one
//! of the update of Eq. (11): `R = Exp(ξ_R) R̂`, `ω = ω̂ + ξ_ω`,
//! `Ω = Ω̂ + ξ_Ω`, error state `ξ = [ξ_R; ξ_ω; ξ_Ω]` with covariance `P`.
//!
//! # Propagation (derivation)
//! With `J_r(x) = D_exp(-x)`, `Exp(x + δ) ≈ Exp(x) Exp(J_r(x) δ)` and
//! `Exp(x + δ) ≈ Exp(J_r(-x) δ) Exp(x)`, the adjoint identity
//! `A Exp(a) Aᵀ = Exp(A a)`, `A = Exp(-Ω̂Δt)` and `R̂⁻ = A R̂ Exp(ω̂Δt)`:
//! ```text
//! R_{k+1} = Exp(-(Ω̂+ξ_Ω)Δt) Exp(ξ_R) R̂ Exp((ω̂+ξ_ω)Δt)
//!         = Exp(-J_r(Ω̂Δt) Δt ξ_Ω) A Exp(ξ_R) R̂ Exp(ω̂Δt) Exp(J_r(ω̂Δt) Δt ξ_ω)
//!         = Exp(A ξ_R + R̂⁻ J_r(ω̂Δt) Δt ξ_ω - J_r(Ω̂Δt) Δt ξ_Ω) R̂⁻ + O(|ξ|²)
//! ```
//! so `ξ⁻ = F ξ` with
//! `F = [[A, R̂⁻ J_r(ω̂Δt) Δt, -J_r(Ω̂Δt) Δt], [0, I, 0], [0, 0, I]]`.
//! With `Ω̂ = 0` the attitude block is the identity, the invariance property
//! the IEKF is built on. The test `f_matches_numerical_linearisation` checks
//! `F` by finite differences.
//!
//! # Process noise
//! White noise on the attitude (left, density `q_rot`, rad²/s) and random
//! walks on `ω` and `Ω` (densities `q_w`, `q_w_sensor`, rad²/s³). With the
//! couplings `B_ω = R̂⁻ J_r(ω̂Δt)` and `B_Ω = -J_r(Ω̂Δt)` held constant over
//! the step, each random walk `u` adds
//! `[[q Δt³/3 B Bᵀ, q Δt²/2 B], [q Δt²/2 Bᵀ, q Δt I]]` on its rows
//! (positive semi-definite; exact as the rates times `Δt` → 0).
//!
//! # Measurement and update (Eq. 11)
//! The registration measures `R̄ = Exp(n) R`, `n ~ N(0, N)`. The innovation
//! `y = Log(R̄ R̂⁻ᵀ) ≈ ξ_R + n` gives `H = [I 0 0]`. With the gain `K` (9x3):
//! `δ = K y`, `(R, ω, Ω) ← (Exp(δ_R) R̂⁻, ω̂⁻ + δ_ω, Ω̂⁻ + δ_Ω)`, Joseph-form
//! `P`, then `P ← G P Gᵀ`, `G = diag(J_l(δ_R), I, I)` (the covariance moved
//! to the new estimate).
//!
//! # The state it keeps
//! The rest of the tracker wants the relative rate of the target in its own
//! frame, `u = ω - Rᵀ Ω` (what the motion within a scan follows), and the
//! wire must restore a filter bit for bit. So the filter keeps
//! `(R, u, Ω)` and the covariance of `[ξ_R; ξ_u; ξ_Ω]`, and uses the
//! derivation above through the map between the two error states:
//! `ξ_u = ξ_ω - R̂ᵀ [Ω̂]ₓ ξ_R - R̂ᵀ ξ_Ω` to first order, i.e.
//! `ξ_pub = T ξ` with `T = [[I, 0, 0], [-R̂ᵀ[Ω̂]ₓ, I, -R̂ᵀ], [0, 0, I]]`.
//! The step is `F_pub = T(R̂⁻, Ω̂) F T(R̂, Ω̂)⁻¹` and `Q_pub = T(R̂⁻, Ω̂) Q
//! T(R̂⁻, Ω̂)ᵀ`; the update's `H = [I 0 0]` is the same (`T` keeps `ξ_R`).
//! The first 6x6 block of the covariance means what the one-rate filter's
//! covariance meant.
//!
//! With `sensor_rate` off, `Ω` stays 0 and uncoupled: Eq. (9) exactly.

use crate::error::FilterError;
use crate::kalman::{Innovation, checked_covariance, symmetrize, update_first_block};
use crate::position::check_step;
use nalgebra::{Matrix3, Rotation3, SMatrix, UnitQuaternion, Vector3};
use spacepose_geometry::so3;

/// A 9x9 covariance of the attitude filter.
pub type Matrix9 = SMatrix<f64, 9, 9>;

/// The right Jacobian of SO(3), `J_r(x) = D_exp(-x)`:
/// `Exp(x + δ) ≈ Exp(x) Exp(J_r(x) δ)`.
pub fn right_jacobian(x: &Vector3<f64>) -> Matrix3<f64> {
    so3::d_exp(&(-x))
}

/// The process-noise densities of one propagation step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeNoise {
    /// White noise on the attitude (rad²/s).
    pub q_rot: f64,
    /// Random walk of the target's rate (rad²/s³).
    pub q_w: f64,
    /// Random walk of the sensor frame's rate (rad²/s³).
    pub q_w_sensor: f64,
}

/// Attitude and angular-velocity estimate of the target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeFilter {
    /// Attitude of the target in the sensor frame.
    pub r_sensor_target: Rotation3<f64>,
    /// Angular velocity of the target relative to the sensor frame, in the
    /// target frame, `u = ω - Rᵀ Ω` (rad/s).
    pub w_target: Vector3<f64>,
    /// Angular velocity of the sensor frame w.r.t. inertial space, in the
    /// sensor frame, `Ω` (rad/s). 0 when `sensor_rate` is off.
    pub w_inertial_sensor: Vector3<f64>,
    /// Covariance of the error `[ξ_R; ξ_u; ξ_Ω]` (rad², rad²/s², rad²/s²).
    pub covariance: Matrix9,
    /// Whether `Ω` is estimated (off: seed 000's model).
    pub sensor_rate: bool,
}

impl AttitudeFilter {
    /// A filter state. Fails on non-finite input or a covariance that is
    /// not symmetric positive definite.
    pub fn new(
        r_sensor_target: Rotation3<f64>,
        w_target: Vector3<f64>,
        w_inertial_sensor: Vector3<f64>,
        covariance: Matrix9,
        sensor_rate: bool,
    ) -> Result<Self, FilterError> {
        let finite = r_sensor_target
            .matrix()
            .iter()
            .chain(w_target.iter())
            .chain(w_inertial_sensor.iter())
            .all(|v| v.is_finite());
        if !finite {
            return Err(FilterError::NonFinite {
                what: "attitude filter state",
            });
        }
        let covariance = checked_covariance(&covariance, "attitude filter covariance")?;
        let mut f = Self {
            r_sensor_target: renormalize(&r_sensor_target),
            w_target,
            w_inertial_sensor,
            covariance,
            sensor_rate,
        };
        if !sensor_rate {
            f.decouple_sensor_rate();
        }
        Ok(f)
    }

    /// Off: `Ω = 0`, uncorrelated with the rest (its variance is kept, and
    /// nothing ever couples to it).
    fn decouple_sensor_rate(&mut self) {
        self.w_inertial_sensor = Vector3::zeros();
        self.covariance.fixed_view_mut::<6, 3>(0, 6).fill(0.0);
        self.covariance.fixed_view_mut::<3, 6>(6, 0).fill(0.0);
    }

    /// The angular velocity of the target w.r.t. inertial space, in the
    /// target frame, `ω = u + Rᵀ Ω` (rad/s).
    pub fn w_inertial_target(&self) -> Vector3<f64> {
        self.w_target + self.r_sensor_target.inverse() * self.w_inertial_sensor
    }

    /// The relative angular velocity in the sensor frame, `R u` (rad/s).
    pub fn w_sensor(&self) -> Vector3<f64> {
        self.r_sensor_target * self.w_target
    }

    /// The propagated mean `Exp(-Ω̂Δt) R̂ Exp(ω̂ Δt)`.
    pub fn predicted_rotation(&self, dt: f64) -> Rotation3<f64> {
        self.step(dt).r_pred
    }

    /// `T` of the module docs at attitude `r` and this `Ω̂`, or its
    /// inverse: `[[I, 0, 0], [∓R̂ᵀ[Ω̂]ₓ, I, ∓R̂ᵀ], [0, 0, I]]`; the identity
    /// when `Ω` is not estimated (it is then known to be 0, and `u = ω`).
    fn error_map(&self, r: &Rotation3<f64>, inverse: bool) -> Matrix9 {
        let mut t = Matrix9::identity();
        if !self.sensor_rate {
            return t;
        }
        let sign = if inverse { 1.0 } else { -1.0 };
        let rt = r.inverse().into_inner() * sign;
        t.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&(rt * self.w_inertial_sensor.cross_matrix()));
        t.fixed_view_mut::<3, 3>(3, 6).copy_from(&rt);
        t
    }

    /// What one propagation over `Δt` needs, computed once.
    fn step(&self, dt: f64) -> Step {
        let turn_sensor = so3::exp(&(-self.w_inertial_sensor * dt));
        let w = self.w_inertial_target();
        let r_pred = renormalize(&(turn_sensor * self.r_sensor_target * so3::exp(&(w * dt))));
        let b_sensor = if self.sensor_rate {
            -right_jacobian(&(self.w_inertial_sensor * dt))
        } else {
            Matrix3::zeros()
        };
        Step {
            dt,
            turn_sensor,
            b_w: r_pred.matrix() * right_jacobian(&(w * dt)),
            b_sensor,
            t_pred: self.error_map(&r_pred, false),
            r_pred,
        }
    }

    /// The transition `F` of the error `[ξ_R; ξ_ω; ξ_Ω]` (module docs;
    /// checked against finite differences by the tests).
    #[cfg(test)]
    fn inertial_transition(&self, dt: f64) -> Matrix9 {
        self.step(dt).inertial_transition()
    }

    /// The transition of the kept error `[ξ_R; ξ_u; ξ_Ω]`,
    /// `T(R̂⁻) F T(R̂)⁻¹` (module docs).
    pub fn transition_matrix(&self, dt: f64) -> Matrix9 {
        self.transition_of(&self.step(dt))
    }

    fn transition_of(&self, step: &Step) -> Matrix9 {
        step.t_pred * step.inertial_transition() * self.error_map(&self.r_sensor_target, true)
    }

    /// The process noise of the kept error accumulated over `Δt`,
    /// `T(R̂⁻) Q T(R̂⁻)ᵀ` (module docs).
    pub fn process_noise(&self, dt: f64, noise: &AttitudeNoise) -> Matrix9 {
        self.process_noise_of(&self.step(dt), noise)
    }

    fn process_noise_of(&self, step: &Step, noise: &AttitudeNoise) -> Matrix9 {
        let q_sensor = if self.sensor_rate {
            noise.q_w_sensor
        } else {
            0.0
        };
        let t = &step.t_pred;
        symmetrize(&(t * step.inertial_noise(noise, q_sensor) * t.transpose()))
    }

    /// The prediction `Δt ≥ 0` seconds ahead; `self` is unchanged.
    pub fn predict(&self, dt: f64, noise: &AttitudeNoise) -> Result<Self, FilterError> {
        check_step(dt, noise.q_rot)?;
        check_step(dt, noise.q_w)?;
        check_step(dt, noise.q_w_sensor)?;
        let step = self.step(dt);
        let f = self.transition_of(&step);
        let p = f * self.covariance * f.transpose() + self.process_noise_of(&step, noise);
        // ω and Ω are constant: u⁻ = ω - R̂⁻ᵀ Ω.
        let w_target = self.w_inertial_target() - step.r_pred.inverse() * self.w_inertial_sensor;
        Ok(Self {
            r_sensor_target: step.r_pred,
            w_target,
            covariance: symmetrize(&p),
            ..*self
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
        let n = checked_covariance(n, "attitude measurement covariance")?;
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
        // Eq. (11): (R, u, Ω) ← (Exp(δ_R) R⁻, u⁻ + δ_u, Ω⁻ + δ_Ω).
        self.r_sensor_target = renormalize(&(so3::exp(&d_rot) * self.r_sensor_target));
        self.w_target += step.correction.fixed_rows::<3>(3);
        self.w_inertial_sensor += step.correction.fixed_rows::<3>(6);
        // Move the covariance to the error around the new estimate.
        let mut g = Matrix9::identity();
        g.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&so3::d_exp(&d_rot));
        self.covariance = symmetrize(&(g * step.covariance * g.transpose()));
        if !self.sensor_rate {
            self.decouple_sensor_rate();
        }
        Ok(innovation)
    }
}

/// One propagation step's mean and couplings (module docs).
struct Step {
    dt: f64,
    /// `Exp(-Ω̂Δt)`, the attitude block of `F`.
    turn_sensor: Rotation3<f64>,
    /// `R̂⁻ = Exp(-Ω̂Δt) R̂ Exp(ω̂Δt)`.
    r_pred: Rotation3<f64>,
    /// `B_ω = R̂⁻ J_r(ω̂Δt)`.
    b_w: Matrix3<f64>,
    /// `B_Ω = -J_r(Ω̂Δt)` (0 when `Ω` is not estimated).
    b_sensor: Matrix3<f64>,
    /// `T(R̂⁻)`.
    t_pred: Matrix9,
}

impl Step {
    /// `F` of `[ξ_R; ξ_ω; ξ_Ω]`.
    fn inertial_transition(&self) -> Matrix9 {
        let mut f = Matrix9::identity();
        f.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(self.turn_sensor.matrix());
        f.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(self.b_w * self.dt));
        f.fixed_view_mut::<3, 3>(0, 6)
            .copy_from(&(self.b_sensor * self.dt));
        f
    }

    /// `Q` of `[ξ_R; ξ_ω; ξ_Ω]`: white attitude noise and the two random
    /// walks (`q_sensor` 0 when `Ω` is not estimated).
    fn inertial_noise(&self, noise: &AttitudeNoise, q_sensor: f64) -> Matrix9 {
        let dt = self.dt;
        let mut q = Matrix9::zeros();
        let mut rr = Matrix3::identity() * (noise.q_rot * dt);
        for (offset, b, density) in [(3, self.b_w, noise.q_w), (6, self.b_sensor, q_sensor)] {
            rr += b * b.transpose() * (density * dt.powi(3) / 3.0);
            let cross = b * (density * dt * dt / 2.0);
            q.fixed_view_mut::<3, 3>(0, offset).copy_from(&cross);
            q.fixed_view_mut::<3, 3>(offset, 0)
                .copy_from(&cross.transpose());
            q.fixed_view_mut::<3, 3>(offset, offset)
                .copy_from(&(Matrix3::identity() * (density * dt)));
        }
        q.fixed_view_mut::<3, 3>(0, 0).copy_from(&rr);
        symmetrize(&q)
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
