//! The world the sensor sees when it is not the estimators' model (issue
//! 25 item 3): the target as built ([`spacepose_model::AsBuilt`]), and a
//! motion within each scan that is not the constant velocity the filter
//! and the motion compensation assume (seed 000 Eq. 8-9):
//!
//! - the scenario's own motion at every instant of the scan (the
//!   torque-free tumble is not uniform; the chaser's legs curve), sampled
//!   every `1 / SAMPLES` of the scan and interpolated (slerp and lerp);
//! - the chaser's attitude jitter: the sensor frame turned by
//!   `Exp(Σ a_i sin(2π f_i t + φ_i) e_i)`, two sines per axis of amplitude
//!   `jitter_deg` and frequencies in `jitter_hz`, continuous over the run;
//! - a relative acceleration (thruster pulses), constant within a scan,
//!   of `acceleration_mps2` in a direction drawn per frame; it vanishes at
//!   the scan end, where the truth is.
//!
//! The frame's truth is the jittered pose at the scan end: what an
//! estimator should report.

use crate::error::SimError;
use nalgebra::{Rotation3, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use spacepose_geometry::{Pose, so3};
use spacepose_model::AsBuilt;
use spacepose_scenario::{Scenario, TruthState};

/// Intervals the scan's motion is sampled in.
const SAMPLES: usize = 32;

/// How the simulated world departs from the estimators' model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Mismatch {
    /// The target as built.
    pub as_built: AsBuilt,
    /// Amplitude of each of the six jitter sines (deg).
    pub jitter_deg: f64,
    /// Range of the jitter frequencies (Hz).
    pub jitter_hz: [f64; 2],
    /// Magnitude of the relative acceleration within a scan (m/s²).
    pub acceleration_mps2: f64,
}

impl Default for Mismatch {
    /// [`AsBuilt::default`], 0.02° of jitter at 0.5-5 Hz (about 0.05° peak
    /// on an axis), 5 mm/s² of acceleration.
    fn default() -> Self {
        Mismatch {
            as_built: AsBuilt::default(),
            jitter_deg: 0.02,
            jitter_hz: [0.5, 5.0],
            acceleration_mps2: 0.005,
        }
    }
}

impl Mismatch {
    /// Fails on a negative, non-finite or inverted value
    /// ([`SimError::InvalidConfig`] naming the field), or an invalid
    /// as-built target ([`SimError::Mismatch`]).
    pub fn validate(&self) -> Result<(), SimError> {
        self.as_built
            .validate()
            .map_err(|e| SimError::Mismatch(e.to_string()))?;
        let [lo, hi] = self.jitter_hz;
        let checks = [
            (
                "mismatch.jitter_deg",
                self.jitter_deg,
                self.jitter_deg >= 0.0,
                "must be finite and >= 0",
            ),
            (
                "mismatch.jitter_hz[0]",
                lo,
                lo > 0.0,
                "must be finite and > 0",
            ),
            (
                "mismatch.jitter_hz[1]",
                hi,
                hi >= lo,
                "must be finite and >= jitter_hz[0]",
            ),
            (
                "mismatch.acceleration_mps2",
                self.acceleration_mps2,
                self.acceleration_mps2 >= 0.0,
                "must be finite and >= 0",
            ),
        ];
        for (field, value, ok, reason) in checks {
            if !(value.is_finite() && ok) {
                return Err(SimError::InvalidConfig {
                    field,
                    value,
                    reason,
                });
            }
        }
        Ok(())
    }

    /// The jitter of a run seeded with `seed`.
    pub fn jitter(&self, seed: u64) -> Jitter {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x717e_b0b0);
        let [lo, hi] = self.jitter_hz;
        let a = self.jitter_deg.to_radians();
        let sines = std::array::from_fn(|k| Sine {
            axis: k % 3,
            amplitude_rad: a,
            hz: rng.random_range(lo..=hi),
            phase: rng.random_range(0.0..std::f64::consts::TAU),
        });
        Jitter { sines }
    }

    /// The motion over the scan `[t_start, t_end]` of frame `frame` (run
    /// seed `seed`) of `scenario`, and the frame's truth.
    pub fn scan_path(
        &self,
        scenario: &dyn Scenario,
        (t_start, t_end): (f64, f64),
        seed: u64,
        frame: u64,
    ) -> (ScanPath, TruthState) {
        let jitter = self.jitter(seed);
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x00ac_ce1e_7a7e);
        rng.set_stream(frame);
        let accel = random_unit(&mut rng) * self.acceleration_mps2;
        let dt = (t_end - t_start).max(0.0) / SAMPLES as f64;
        let pose_at = |t: f64| {
            let truth = scenario.pose_at(t);
            let j = jitter.at(t).inverse();
            let lag = t - t_end;
            Pose::new(
                j * truth.rotation,
                j * (truth.translation + accel * (0.5 * lag * lag)),
            )
        };
        let poses: Vec<Pose> = (0..=SAMPLES)
            .map(|k| pose_at(t_start + k as f64 * dt))
            .collect();
        let steps = poses
            .windows(2)
            .map(|w| so3::log(&(w[0].rotation.inverse() * w[1].rotation)))
            .collect();
        let mut truth = scenario.state_at(t_end);
        truth.t_sensor_target = poses[SAMPLES];
        let path = ScanPath {
            t_start,
            dt,
            poses,
            steps,
        };
        (path, truth)
    }
}

/// One sine of the jitter about one sensor axis.
#[derive(Debug, Clone, Copy)]
struct Sine {
    axis: usize,
    amplitude_rad: f64,
    hz: f64,
    phase: f64,
}

/// The chaser's attitude jitter: six sines, two per sensor axis.
#[derive(Debug, Clone)]
pub struct Jitter {
    sines: [Sine; 6],
}

impl Jitter {
    /// The sensor frame's deviation at `t` (nominal ← actual).
    pub fn at(&self, t: f64) -> Rotation3<f64> {
        let mut v = Vector3::zeros();
        for s in &self.sines {
            v[s.axis] += s.amplitude_rad * (std::f64::consts::TAU * s.hz * t + s.phase).sin();
        }
        so3::exp(&v)
    }
}

/// The target's pose sampled over one scan.
#[derive(Debug, Clone)]
pub struct ScanPath {
    t_start: f64,
    dt: f64,
    poses: Vec<Pose>,
    /// `log(R_kᵀ R_{k+1})` of each interval.
    steps: Vec<Vector3<f64>>,
}

impl ScanPath {
    /// The interval holding `t` and the fraction of it elapsed (clamped to
    /// the scan).
    #[inline]
    fn locate(&self, t: f64) -> (usize, f64) {
        if self.dt <= 0.0 {
            return (self.steps.len().saturating_sub(1), 1.0);
        }
        let x = ((t - self.t_start) / self.dt).clamp(0.0, self.steps.len() as f64);
        let k = (x.floor() as usize).min(self.steps.len() - 1);
        (k, x - k as f64)
    }

    /// Position of the centre of mass at `t`, sensor frame.
    #[inline]
    pub fn position(&self, t: f64) -> Vector3<f64> {
        let (k, f) = self.locate(t);
        self.poses[k].translation * (1.0 - f) + self.poses[k + 1].translation * f
    }

    /// Body → sensor rotation at `t`.
    #[inline]
    pub fn rotation(&self, t: f64) -> Rotation3<f64> {
        let (k, f) = self.locate(t);
        self.poses[k].rotation * so3::exp(&(self.steps[k] * f))
    }
}

fn random_unit(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let n: f64 = v.norm();
        if n > 1e-3 && n <= 1.0 {
            return v / n;
        }
    }
}

#[cfg(test)]
#[path = "mismatch_tests.rs"]
mod tests;
