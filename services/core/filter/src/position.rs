//! Linear Kalman filter on the relative position (seed 000 §3.2, Eq. 8, 10).
//!
//! State `x = [p; v]`: position `p` and velocity `v` of the target origin
//! (centre of mass) in the sensor frame.
//!
//! Prediction over `Δt` (constant velocity, Eq. 8):
//! `x⁻ = F x`, `F = [[I, Δt I], [0, I]]`,
//! `P⁻ = F P Fᵀ + Q` with the white-acceleration process noise of spectral
//! density `q_pos` (m²/s³), integrated exactly over the step:
//! `Q = q_pos [[Δt³/3 I, Δt²/2 I], [Δt²/2 I, Δt I]]`.
//!
//! Update with a measured position `p̄` of covariance `N` (Eq. 10):
//! `H = [I 0]`, `y = p̄ - p⁻`, `x⁺ = x⁻ + K y`, Joseph-form covariance
//! (see [`crate::kalman`]).

use crate::error::FilterError;
use crate::kalman::{Innovation, checked_covariance, symmetrize, update_first_block};
use nalgebra::{Matrix3, Matrix6, Vector3};

/// Position/velocity estimate of the target in the sensor frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PositionFilter {
    /// Position of the target origin in the sensor frame (m).
    pub p_sensor: Vector3<f64>,
    /// Velocity of the target origin in the sensor frame (m/s).
    pub v_sensor: Vector3<f64>,
    /// Covariance of `[p; v]` (m², m²/s).
    pub covariance: Matrix6<f64>,
}

impl PositionFilter {
    /// A filter state. Fails on non-finite input or a covariance that is not
    /// symmetric positive definite.
    pub fn new(
        p_sensor: Vector3<f64>,
        v_sensor: Vector3<f64>,
        covariance: Matrix6<f64>,
    ) -> Result<Self, FilterError> {
        if !p_sensor
            .iter()
            .chain(v_sensor.iter())
            .all(|v| v.is_finite())
        {
            return Err(FilterError::NonFinite {
                what: "position filter state",
            });
        }
        let covariance = checked_covariance(&covariance, "position filter covariance")?;
        Ok(Self {
            p_sensor,
            v_sensor,
            covariance,
        })
    }

    /// The transition matrix `F = [[I, Δt I], [0, I]]` of Eq. (8).
    pub fn transition_matrix(dt: f64) -> Matrix6<f64> {
        let mut f = Matrix6::identity();
        f.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(Matrix3::identity() * dt));
        f
    }

    /// The white-acceleration process noise accumulated over `Δt`.
    pub fn process_noise(dt: f64, q_pos: f64) -> Matrix6<f64> {
        let i = Matrix3::<f64>::identity();
        let mut q = Matrix6::zeros();
        q.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(i * (q_pos * dt.powi(3) / 3.0)));
        q.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(i * (q_pos * dt * dt / 2.0)));
        q.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&(i * (q_pos * dt * dt / 2.0)));
        q.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&(i * (q_pos * dt)));
        q
    }

    /// The prediction `Δt ≥ 0` seconds ahead (Eq. 8); `self` is unchanged.
    pub fn predict(&self, dt: f64, q_pos: f64) -> Result<Self, FilterError> {
        check_step(dt, q_pos)?;
        let f = Self::transition_matrix(dt);
        let covariance =
            symmetrize(&(f * self.covariance * f.transpose() + Self::process_noise(dt, q_pos)));
        Ok(Self {
            p_sensor: self.p_sensor + self.v_sensor * dt,
            v_sensor: self.v_sensor,
            covariance,
        })
    }

    /// The innovation `y = p̄ - p` of a position measurement with noise `N`.
    pub fn innovation(
        &self,
        p_measured: &Vector3<f64>,
        n: &Matrix3<f64>,
    ) -> Result<Innovation, FilterError> {
        if !p_measured.iter().all(|v| v.is_finite()) {
            return Err(FilterError::NonFinite {
                what: "measured position",
            });
        }
        let n = checked_covariance(n, "position measurement covariance")?;
        Ok(Innovation::new(
            p_measured - self.p_sensor,
            &self.covariance,
            &n,
        ))
    }

    /// Fuses a position measurement (Eq. 10) into this (predicted) state and
    /// returns the innovation it used.
    pub fn update(
        &mut self,
        p_measured: &Vector3<f64>,
        n: &Matrix3<f64>,
    ) -> Result<Innovation, FilterError> {
        let innovation = self.innovation(p_measured, n)?;
        let step = update_first_block(&self.covariance, &innovation, n)?;
        self.p_sensor += step.correction.fixed_rows::<3>(0);
        self.v_sensor += step.correction.fixed_rows::<3>(3);
        self.covariance = step.covariance;
        Ok(innovation)
    }
}

/// `Δt` must be finite and non-negative, the noise density finite and ≥ 0.
pub(crate) fn check_step(dt: f64, q: f64) -> Result<(), FilterError> {
    if !dt.is_finite() || !q.is_finite() {
        return Err(FilterError::NonFinite {
            what: "time step or process noise",
        });
    }
    if dt < 0.0 {
        return Err(FilterError::InvalidTimeStep { dt_s: dt });
    }
    if q < 0.0 {
        return Err(FilterError::InvalidConfig(format!(
            "negative process noise {q}"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    fn initial() -> PositionFilter {
        let mut p0 = Matrix6::identity() * 0.01;
        for i in 3..6 {
            p0[(i, i)] = 1.0;
        }
        PositionFilter::new(Vector3::new(0.1, -0.2, 20.0), Vector3::zeros(), p0).unwrap()
    }

    #[test]
    fn process_noise_matches_numerical_integral() {
        // Q = ∫₀^Δt F(s) G q Gᵀ F(s)ᵀ ds with G = [0; I], midpoint rule.
        let (dt, q, n) = (0.7, 0.3, 20_000);
        let mut g = nalgebra::Matrix6x3::zeros();
        g.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&Matrix3::identity());
        let mut acc = Matrix6::zeros();
        for k in 0..n {
            let s = (k as f64 + 0.5) * dt / n as f64;
            let f = PositionFilter::transition_matrix(s);
            acc += f * g * g.transpose() * f.transpose() * (q * dt / n as f64);
        }
        assert!((acc - PositionFilter::process_noise(dt, q)).abs().max() < 1e-8);
    }

    #[test]
    fn converges_to_constant_velocity() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let sigma = 0.01;
        let noise = Normal::new(0.0, sigma).unwrap();
        let (p0, v) = (
            Vector3::new(0.3, -0.1, 20.0),
            Vector3::new(0.05, -0.02, -0.1),
        );
        let n = Matrix3::identity() * sigma * sigma;
        let mut f = initial();
        let dt = 0.5;
        for k in 1..=40 {
            let t = k as f64 * dt;
            let truth = p0 + v * t;
            let meas = truth + Vector3::from_fn(|_, _| noise.sample(&mut rng));
            f = f.predict(dt, 1e-8).unwrap();
            f.update(&meas, &n).unwrap();
            assert!(
                f.covariance.cholesky().is_some(),
                "covariance lost PD at step {k}"
            );
            assert_eq!(f.covariance, f.covariance.transpose());
        }
        let v_err = (f.v_sensor - v).norm();
        let p_err = (f.p_sensor - (p0 + v * 20.0)).norm();
        println!("position KF after 40 updates: |v̂-v| = {v_err:.2e} m/s, |p̂-p| = {p_err:.2e} m");
        assert!(v_err < 2e-3, "velocity error {v_err}");
        assert!(p_err < 2.0 * sigma, "position error {p_err}");
        // The filter's own 3σ bound on each velocity axis must cover the error.
        for i in 0..3 {
            assert!((f.v_sensor[i] - v[i]).abs() < 3.0 * f.covariance[(3 + i, 3 + i)].sqrt());
        }
    }

    #[test]
    fn rejects_bad_input() {
        let f = initial();
        assert!(f.predict(-0.1, 1e-3).is_err());
        assert!(f.predict(f64::NAN, 1e-3).is_err());
        assert!(
            f.innovation(&Vector3::new(f64::NAN, 0.0, 0.0), &Matrix3::identity())
                .is_err()
        );
        assert!(f.innovation(&Vector3::zeros(), &Matrix3::zeros()).is_err());
        assert!(
            PositionFilter::new(Vector3::zeros(), Vector3::zeros(), -Matrix6::identity()).is_err()
        );
        // Δt = 0 is the identity.
        assert_eq!(f.predict(0.0, 1e-3).unwrap(), f);
    }
}
