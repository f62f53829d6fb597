//! Sensor configuration: scan pattern, timing, switchable effects and noise
//! parameters.

use crate::clutter::Facility;
use crate::detection::DetectionParams;
use crate::error::{SimError, check_positive};
use crate::pattern::ScanPattern;

/// Largest number of rays accepted per frame (guards against absurd configs).
pub const MAX_RAYS_PER_FRAME: usize = 50_000_000;

/// Scan time of the seed-002 raster (s): seed 002 §3.2 leaves the motion
/// blur out because the scan takes "a few centiseconds", against the
/// 1 Hz frame rate. With the 1 s scan used before, ENVISAT's 2°/s rotation
/// in the `ellipse` scenario smeared the solar array's tip by up to 0.7 m.
pub const RASTER_SCAN_TIME_S: f64 = 0.05;

/// The range extent of a 5 ns pulse, `c τ / 2` (m): echoes farther apart
/// are resolved (`SensorConfig::echo_separation_m`).
pub const DEFAULT_ECHO_SEPARATION_M: f64 = 0.75;

/// Which effects the simulator applies; each can be switched independently.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Effects {
    /// Gaussian range noise σ_RANGE (seed 002 §3.2, seed 004 §IV.A).
    pub range_noise: bool,
    /// Line-of-sight noise σ_LOS: direction rotated by a normal angle about a
    /// uniform azimuth (seed 002 §3.2).
    pub los_noise: bool,
    /// Outliers with probability P_O and range σ = 4 σ_RANGE (seed 002).
    pub outliers: bool,
    /// Random drop with the probability of detection of seed 002 Eq. (4).
    pub detection: bool,
    /// Beam divergence: 5 rays, γ ~ U[0, β], weights of seed 004 Eq. (18).
    pub beam_divergence: bool,
    /// One reflected ray per incoming ray inside the cone α ≤ sqrt(2/η)
    /// (seed 004 §IV.A).
    pub reflections: bool,
    /// Target motion during the scan (constant velocity and angular velocity).
    pub motion_blur: bool,
    /// Test-facility background: floor, back wall, robot arm (seed 000 §4.1).
    pub clutter: bool,
}

impl Effects {
    /// Every effect, clutter included.
    pub fn all() -> Self {
        Effects {
            range_noise: true,
            los_noise: true,
            outliers: true,
            detection: true,
            beam_divergence: true,
            reflections: true,
            motion_blur: true,
            clutter: true,
        }
    }

    /// No effect: ideal geometric ray casting at the scan-end pose.
    pub fn none() -> Self {
        Effects {
            range_noise: false,
            los_noise: false,
            outliers: false,
            detection: false,
            beam_divergence: false,
            reflections: false,
            motion_blur: false,
            clutter: false,
        }
    }
}

impl Default for Effects {
    /// Every effect but clutter (space has no facility background).
    fn default() -> Self {
        Effects {
            clutter: false,
            ..Effects::all()
        }
    }
}

/// How a target surface sends the laser back (the return factor of the
/// detection model and the specular reflections).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SurfaceModel {
    /// Seed 004 Eq. (17) with per-frame domain randomisation (Table I): `k_d`
    /// and `η` drawn per material, so that solar panels and MLI are mostly
    /// specular. The model of the Mid-40 experiments (seeds 000 and 004).
    #[default]
    Phong,
    /// Seed 002 Eq. (6): a well-resolved Lambertian target, return
    /// `ρ_T cos θ / R²`, no specular lobe and so no secondary reflection.
    /// The model of seed 002's template-matching simulations.
    Lambertian,
}

/// Full description of the simulated sensor.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorConfig {
    /// Scan pattern.
    pub pattern: ScanPattern,
    /// Ray rate of a rosette (rays/s). For a raster, the grid fixes the ray
    /// count and this field is informative only (grid size / integration time).
    pub points_per_second: f64,
    /// Integration time of one frame (s): the scan covers
    /// `[scan_end - integration_time_s, scan_end]`.
    pub integration_time_s: f64,
    /// Switchable effects.
    pub effects: Effects,
    /// σ_RANGE, standard deviation of the range noise (m).
    pub range_sigma_m: f64,
    /// σ_LOS, standard deviation of the pointing (line-of-sight) error (deg).
    pub los_sigma_deg: f64,
    /// P_O, probability that a detected point is an outlier.
    pub outlier_probability: f64,
    /// Ratio of the outlier range σ to σ_RANGE (4 in seed 002).
    pub outlier_sigma_factor: f64,
    /// β, beam divergence half-angle at 1/e² intensity (deg, seed 004 Eq. 18).
    pub beam_divergence_deg: f64,
    /// Number of divergent rays per beam (5 in seed 004; at most
    /// [`crate::MAX_RAYS_PER_BEAM`]).
    pub divergent_rays: usize,
    /// Echoes of one beam farther apart in depth than this (m) come back as
    /// separate pulses, and the strongest is reported; closer ones merge
    /// into their intensity-weighted average (seed 004 §IV.A averages them
    /// all: `f64::INFINITY`). Default 0.75 m, the range extent of a 5 ns
    /// pulse (`docs/design/echo-separation.md`).
    pub echo_separation_m: f64,
    /// Maximum range (m): farther surfaces give no echo.
    pub max_range_m: f64,
    /// Detection model parameters (seed 002 Table 1).
    pub detection: DetectionParams,
    /// Reflection model of the target's surfaces.
    pub surface_model: SurfaceModel,
    /// Layout of the test-facility background used when `effects.clutter`.
    pub facility: Facility,
}

impl Default for SensorConfig {
    /// The Livox Mid-40 with every effect but clutter.
    fn default() -> Self {
        SensorConfig::livox_mid40()
    }
}

impl SensorConfig {
    /// Default integration time of the Mid-40 model (s), chosen so that a
    /// `deos` target at 10 m on the boresight returns about 10,000 points
    /// with the default effects (seed 004 §IV.C: adaptive integration time
    /// for ~10,000 target points). Measured over 16 random attitudes with
    /// the Mid-40 receiver: mean 10,043 points with the default effects,
    /// 11,424 with no effect at all (54,000 rays).
    pub const MID40_INTEGRATION_TIME_S: f64 = 0.54;

    /// Livox Mid-40: rosette over a 38.4° circle at 100,000 points/s,
    /// σ_RANGE = 2 cm (seed 004 §IV.A), β = 0.28°, five divergent rays.
    ///
    /// Values not given by seed 004 and their source:
    /// - σ_LOS = 0.05°: the datasheet bounds the angular error by 0.1° (1σ);
    ///   Brazeal et al. (seed 004 ref. 58) find the sensor better than its
    ///   specification, so we take half the bound.
    /// - P_O = 5 %: the lower end of seed 002's 5-7 %, because beam
    ///   divergence and reflections already produce explicit artefacts here.
    /// - Maximum range 260 m (datasheet, at 80 % reflectivity).
    /// - Detection: seed 002's detector chain (Table 1) scaled to the
    ///   Mid-40 datasheet range, 90 m at 10 % reflectance
    ///   ([`DetectionParams::livox_mid40`]).
    pub fn livox_mid40() -> Self {
        SensorConfig {
            pattern: ScanPattern::livox_mid40(),
            points_per_second: 100_000.0,
            integration_time_s: Self::MID40_INTEGRATION_TIME_S,
            effects: Effects::default(),
            range_sigma_m: 0.02,
            los_sigma_deg: 0.05,
            outlier_probability: 0.05,
            outlier_sigma_factor: 4.0,
            beam_divergence_deg: 0.28,
            divergent_rays: 5,
            echo_separation_m: DEFAULT_ECHO_SEPARATION_M,
            max_range_m: 260.0,
            detection: DetectionParams::livox_mid40(),
            surface_model: SurfaceModel::Phong,
            facility: Facility::default(),
        }
    }

    /// The raster sensor of seed 002 §4.1 and Table 1: 40°x40° at 1° (41x41
    /// rays including both edges), frames at 1 Hz each scanned in
    /// [`RASTER_SCAN_TIME_S`], σ_RANGE = 25 mm, σ_LOS = 0.0007°,
    /// P_O = 6 % (middle of 5-7 %), beam divergence 0.02°, and seed 002's
    /// Lambertian return (Eq. 6).
    ///
    /// Why Lambertian: seed 002 computes every echo's SNR from `ρ_T cos θ`
    /// and reports about 490 points at 20 m and 120 at 50 m. With seed 004's
    /// Phong draws instead, the solar array (`k_d` ≤ 0.1, ρ_T = 0.175) drops
    /// below the detection threshold of Table 1's receiver at any range
    /// beyond a few metres and ENVISAT at 50 m kept 46 of its 95 geometric
    /// points (seed 3, 40 random attitudes).
    pub fn raster_seed002() -> Self {
        let pattern = ScanPattern::raster_seed002();
        let rays = pattern.ray_count(1.0, 1.0);
        SensorConfig {
            pattern,
            points_per_second: rays / RASTER_SCAN_TIME_S,
            integration_time_s: RASTER_SCAN_TIME_S,
            effects: Effects::default(),
            range_sigma_m: 0.025,
            los_sigma_deg: 0.0007,
            outlier_probability: 0.06,
            outlier_sigma_factor: 4.0,
            beam_divergence_deg: 0.02,
            divergent_rays: 5,
            echo_separation_m: DEFAULT_ECHO_SEPARATION_M,
            max_range_m: 1000.0,
            detection: DetectionParams::seed002(),
            surface_model: SurfaceModel::Lambertian,
            facility: Facility::default(),
        }
    }

    /// Number of rays of one frame.
    pub fn rays_per_frame(&self) -> usize {
        self.pattern
            .ray_count(self.integration_time_s, self.points_per_second) as usize
    }

    /// Rejects NaN, infinite, non-positive and out-of-range values.
    pub fn validate(&self) -> Result<(), SimError> {
        match self.pattern {
            ScanPattern::Rosette {
                fov_deg,
                prism_rates_hz,
            } => {
                check_range("pattern.fov_deg", fov_deg, 0.0, 180.0)?;
                for rate in prism_rates_hz {
                    check_finite_nonzero("pattern.prism_rates_hz", rate)?;
                }
            }
            ScanPattern::Raster {
                fov_x_deg,
                fov_y_deg,
                step_deg,
            } => {
                check_range("pattern.fov_x_deg", fov_x_deg, 0.0, 180.0)?;
                check_range("pattern.fov_y_deg", fov_y_deg, 0.0, 180.0)?;
                check_positive("pattern.step_deg", step_deg)?;
            }
        }
        check_positive("points_per_second", self.points_per_second)?;
        check_positive("integration_time_s", self.integration_time_s)?;
        check_positive("range_sigma_m", self.range_sigma_m)?;
        check_positive("los_sigma_deg", self.los_sigma_deg)?;
        check_positive("outlier_sigma_factor", self.outlier_sigma_factor)?;
        check_positive("beam_divergence_deg", self.beam_divergence_deg)?;
        check_positive("max_range_m", self.max_range_m)?;
        let p = self.outlier_probability;
        if !(0.0..=1.0).contains(&p) {
            return Err(SimError::InvalidConfig {
                field: "outlier_probability",
                value: p,
                reason: "must be in [0, 1]",
            });
        }
        if self.divergent_rays == 0 || self.divergent_rays > crate::MAX_RAYS_PER_BEAM {
            return Err(SimError::InvalidConfig {
                field: "divergent_rays",
                value: self.divergent_rays as f64,
                reason: "must be in [1, MAX_RAYS_PER_BEAM = 16]",
            });
        }
        if self.echo_separation_m.is_nan() || self.echo_separation_m <= 0.0 {
            return Err(SimError::InvalidConfig {
                field: "echo_separation_m",
                value: self.echo_separation_m,
                reason: "must be > 0 (infinite: seed 004's average of every echo)",
            });
        }
        let rays = self
            .pattern
            .ray_count(self.integration_time_s, self.points_per_second);
        if !(rays >= 1.0 && rays <= MAX_RAYS_PER_FRAME as f64) {
            return Err(SimError::RayCount {
                rays,
                max: MAX_RAYS_PER_FRAME,
            });
        }
        self.detection.validate()?;
        self.facility.validate()
    }
}

fn check_finite_nonzero(field: &'static str, value: f64) -> Result<(), SimError> {
    if value.is_finite() && value != 0.0 {
        Ok(())
    } else {
        Err(SimError::InvalidConfig {
            field,
            value,
            reason: "must be finite and non-zero",
        })
    }
}

fn check_range(field: &'static str, value: f64, lo: f64, hi: f64) -> Result<(), SimError> {
    if value.is_finite() && value > lo && value <= hi {
        Ok(())
    } else {
        Err(SimError::InvalidConfig {
            field,
            value,
            reason: "out of range",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_valid_and_clutter_is_off_by_default() {
        for c in [
            SensorConfig::livox_mid40(),
            SensorConfig::raster_seed002(),
            SensorConfig::default(),
        ] {
            c.validate().unwrap();
            assert!(!c.effects.clutter);
            assert!(c.effects.range_noise && c.effects.reflections && c.effects.motion_blur);
        }
        assert_eq!(SensorConfig::raster_seed002().rays_per_frame(), 41 * 41);
        assert!(!Effects::none().detection && Effects::all().clutter);
    }

    #[test]
    fn validation_rejects_nan_and_non_positive_values() {
        let mut c = SensorConfig::livox_mid40();
        c.integration_time_s = f64::NAN;
        assert!(matches!(
            c.validate(),
            Err(SimError::InvalidConfig {
                field: "integration_time_s",
                ..
            })
        ));
        let mut c = SensorConfig::livox_mid40();
        c.points_per_second = 0.0;
        assert!(c.validate().is_err());
        let mut c = SensorConfig::livox_mid40();
        c.range_sigma_m = -0.01;
        assert!(c.validate().is_err());
        let mut c = SensorConfig::livox_mid40();
        c.outlier_probability = 1.5;
        assert!(c.validate().is_err());
        let mut c = SensorConfig::raster_seed002();
        c.pattern = ScanPattern::Raster {
            fov_x_deg: 40.0,
            fov_y_deg: 40.0,
            step_deg: f64::NAN,
        };
        assert!(c.validate().is_err());
        let mut c = SensorConfig::livox_mid40();
        c.integration_time_s = 1e6;
        assert!(matches!(c.validate(), Err(SimError::RayCount { .. })));
        let mut c = SensorConfig::livox_mid40();
        c.detection.temperature_k = f64::INFINITY;
        assert!(c.validate().is_err());
    }
}
