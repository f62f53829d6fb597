//! The sensor's measurement of one beam echo: the detection draw, outliers,
//! range noise and line-of-sight noise (seed 002 §3.2), in that order of
//! random draws.

use crate::config::SensorConfig;
use crate::detection::DetectionModel;
use crate::frame::{INTENSITY_REFERENCE_M2, ReturnKind};
use crate::optics::tilt;
use crate::scene::BeamEcho;
use nalgebra::Vector3;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use spacepose_geometry::Point;
use std::f64::consts::TAU;

/// Everything the measurement of an echo needs, fixed during one frame.
pub(crate) struct Measurement<'a> {
    /// The sensor configuration (effects, σ_RANGE, P_O, outlier σ factor).
    config: &'a SensorConfig,
    /// The receiver's detection model (seed 002 Eq. 4-9).
    detection: &'a DetectionModel,
    /// σ_LOS (rad).
    los_sigma: f64,
}

impl<'a> Measurement<'a> {
    /// The measurement of one frame by the sensor `config` with the receiver `detection`.
    pub fn new(config: &'a SensorConfig, detection: &'a DetectionModel) -> Self {
        Measurement {
            config,
            detection,
            los_sigma: config.los_sigma_deg.to_radians(),
        }
    }

    /// The point measured from `echo` of the beam emitted along `dir` (unit,
    /// sensor frame) at time `t`, and what produced it; `None` when the echo
    /// is not detected.
    pub fn measure(
        &self,
        t: f64,
        dir: &Vector3<f64>,
        echo: &BeamEcho,
        rng: &mut ChaCha8Rng,
    ) -> Option<(Point, ReturnKind)> {
        if self.config.effects.detection && self.missed(echo, rng) {
            return None;
        }
        let (range, kind) = self.measured_range(echo, rng);
        let out_dir = self.measured_direction(dir, rng);
        let intensity = (echo.intensity * INTENSITY_REFERENCE_M2) as f32;
        Some((Point::from_vector(&(out_dir * range), intensity, t), kind))
    }

    /// Whether `echo` goes undetected: Eq. (4)-(9), then a uniform draw
    /// (seed 002 §3.2). Written as `u >= P_D` so a NaN `P_D` keeps the point.
    fn missed(&self, echo: &BeamEcho, rng: &mut ChaCha8Rng) -> bool {
        let p_d = self
            .detection
            .probability(self.detection.snr(echo.intensity));
        rng.random::<f64>() >= p_d
    }

    /// The measured range and what produced it: an outlier with probability
    /// P_O (range σ = outlier factor × σ_RANGE), else the echo's depth with
    /// range noise σ_RANGE, each when its effect is on.
    fn measured_range(&self, echo: &BeamEcho, rng: &mut ChaCha8Rng) -> (f64, ReturnKind) {
        let c = self.config;
        let mut kind = if echo.clutter {
            ReturnKind::Clutter
        } else {
            ReturnKind::Target
        };
        let mut range = echo.depth;
        if c.effects.outliers && rng.random_bool(c.outlier_probability) {
            let n: f64 = rng.sample(StandardNormal);
            range += n * c.outlier_sigma_factor * c.range_sigma_m;
            kind = ReturnKind::Outlier;
        } else if c.effects.range_noise {
            let n: f64 = rng.sample(StandardNormal);
            range += n * c.range_sigma_m;
        }
        (range, kind)
    }

    /// The measured direction of the beam emitted along `dir`: with
    /// line-of-sight noise, tilted by a normal angle about a uniform azimuth
    /// (seed 002 §3.2).
    fn measured_direction(&self, dir: &Vector3<f64>, rng: &mut ChaCha8Rng) -> Vector3<f64> {
        if self.config.effects.los_noise {
            let n: f64 = rng.sample(StandardNormal);
            tilt(dir, n * self.los_sigma, rng.random_range(0.0..TAU))
        } else {
            *dir
        }
    }
}
