//! Configuration of the relative-motion filter.

use crate::error::FilterError;
use serde::{Deserialize, Serialize};

/// Tuning of [`crate::RelativeMotionFilter`]. Process-noise densities are in
/// SI units (continuous-time spectral densities); angles given in degrees say
/// so in their names.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FilterConfig {
    /// White-acceleration spectral density of the position filter (m²/s³).
    pub q_pos: f64,
    /// White-noise density on the attitude (rad²/s).
    pub q_rot: f64,
    /// Random-walk density of the angular velocity (rad²/s³). 3e-5: a
    /// torque-free tumble of an unknown inertia changes its body rate by
    /// about (ΔI/I) ω² = 0.2 × (10°/s)² ≈ 0.006 rad/s², i.e. q_w ≈ 4e-5;
    /// 1e-6 made the filter trust its constant rate over the measurements
    /// once these were given their real weight
    /// (`docs/design/measurement-covariance.md`).
    pub q_w: f64,
    /// Estimate the sensor frame's own angular velocity `Ω` beside the
    /// target's (`crate::attitude`; `docs/design/sensor-frame-rate.md`).
    /// Off (the default): seed 000's constant relative rate (Eq. 9). Off by
    /// default until the clutter demo's start-up with it is understood: its
    /// end-to-end test failed in 3 of 4 full-suite runs with it on (the
    /// design note).
    pub sensor_rate: bool,
    /// Random-walk density of the sensor frame's angular velocity
    /// (rad²/s³). 1e-6: the fly-around turns the chaser by up to about
    /// 2-3°/s and changes that turn over tens of seconds (≈ 3e-4 rad/s²,
    /// whose square is 1e-7); ten times that follows a change within a few
    /// frames.
    pub q_w_sensor: f64,
    /// Initial uncertainty of the sensor frame's angular velocity, per axis
    /// (deg/s, 1σ; it starts at 0): a chaser keeping a target in view turns
    /// at a few degrees a second at most.
    pub initial_sigma_w_sensor_degps: f64,
    /// Fixed attitude measurement noise, per axis (deg, 1σ).
    pub sigma_rot_deg: f64,
    /// Fixed position measurement noise, per axis (m, 1σ).
    pub sigma_pos_m: f64,
    /// Use the registration's covariance when `update` receives one; when
    /// false the fixed noise above is always used.
    pub use_registration_covariance: bool,
    /// Factor applied to the registration's covariance here. Default 1:
    /// the tracker already publishes its covariance scaled by its
    /// `measurement_covariance_scale` (and ct-ndt's attitude by
    /// `ct_ndt_attitude_covariance_scale`), so what it publishes is what
    /// the filter fuses.
    pub registration_covariance_scale: f64,
    /// Initial attitude uncertainty, per axis (deg, 1σ).
    pub initial_sigma_rot_deg: f64,
    /// Initial position uncertainty, per axis (m, 1σ).
    pub initial_sigma_pos_m: f64,
    /// Initial velocity uncertainty, per axis (m/s, 1σ).
    pub initial_sigma_v_mps: f64,
    /// Initial angular-velocity uncertainty, per axis (deg/s, 1σ). Large:
    /// the filter starts at ω = 0 unless told otherwise (seed 000 §5.2).
    pub initial_sigma_w_degps: f64,
    /// Gate on the squared Mahalanobis distance of the 6-D pose innovation
    /// (the NIS): a measurement above it is not fused. Default χ²₆ at
    /// 99.9 %, 22.46; `inf` or `None` accepts everything. On the
    /// development seeds it caught registrations 10-20 cm off across the
    /// line of sight and changed nothing else
    /// (`docs/design/filter-tuning.md`).
    pub gate_mahalanobis2: Option<f64>,
}

/// χ²(6) at 99.9 %: the default gate.
pub const CHI2_6_999: f64 = 22.46;

impl Default for FilterConfig {
    fn default() -> Self {
        Self {
            q_pos: 1e-4,
            q_rot: 1e-6,
            q_w: 3e-5,
            sensor_rate: false,
            q_w_sensor: 1e-6,
            initial_sigma_w_sensor_degps: 2.0,
            sigma_rot_deg: 1.0,
            sigma_pos_m: 0.02,
            use_registration_covariance: true,
            registration_covariance_scale: 1.0,
            initial_sigma_rot_deg: 2.0,
            initial_sigma_pos_m: 0.05,
            initial_sigma_v_mps: 0.5,
            initial_sigma_w_degps: 30.0,
            // A partial `[filter]` section takes its missing keys from
            // here, so this is what the services run with.
            gate_mahalanobis2: Some(CHI2_6_999),
        }
    }
}

impl FilterConfig {
    /// Checks every value: finite, noise densities ≥ 0, standard deviations
    /// and scale > 0, the gate > 0 (`inf` allowed: off). Fails on NaN.
    pub fn validate(&self) -> Result<(), FilterError> {
        let non_negative = [
            ("q_pos", self.q_pos),
            ("q_rot", self.q_rot),
            ("q_w", self.q_w),
            ("q_w_sensor", self.q_w_sensor),
        ];
        for (name, v) in non_negative {
            if !v.is_finite() || v < 0.0 {
                return Err(FilterError::InvalidConfig(format!(
                    "{name} = {v} must be finite and >= 0"
                )));
            }
        }
        let positive = [
            ("sigma_rot_deg", self.sigma_rot_deg),
            ("sigma_pos_m", self.sigma_pos_m),
            (
                "registration_covariance_scale",
                self.registration_covariance_scale,
            ),
            ("initial_sigma_rot_deg", self.initial_sigma_rot_deg),
            ("initial_sigma_pos_m", self.initial_sigma_pos_m),
            ("initial_sigma_v_mps", self.initial_sigma_v_mps),
            ("initial_sigma_w_degps", self.initial_sigma_w_degps),
            (
                "initial_sigma_w_sensor_degps",
                self.initial_sigma_w_sensor_degps,
            ),
            (
                "gate_mahalanobis2",
                self.gate_mahalanobis2
                    .filter(|g| *g != f64::INFINITY)
                    .unwrap_or(1.0),
            ),
        ];
        for (name, v) in positive {
            if !v.is_finite() || v <= 0.0 {
                return Err(FilterError::InvalidConfig(format!(
                    "{name} = {v} must be finite and > 0"
                )));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_valid_and_round_trips() {
        let c = FilterConfig::default();
        c.validate().unwrap();
        let text = toml::to_string(&c).unwrap();
        let back: FilterConfig = toml::from_str(&text).unwrap();
        assert_eq!(back, c);
        let partial: FilterConfig = toml::from_str("q_w = 1e-8\n").unwrap();
        assert_eq!(partial.q_w, 1e-8);
        assert_eq!(partial.q_pos, c.q_pos);
        // Absent = the default gate, as the deploy examples say.
        assert_eq!(partial.gate_mahalanobis2, Some(CHI2_6_999));
        let off: FilterConfig = toml::from_str("gate_mahalanobis2 = inf\n").unwrap();
        assert_eq!(off.gate_mahalanobis2, Some(f64::INFINITY));
        off.validate().unwrap();
    }

    #[test]
    fn rejects_unknown_fields_and_bad_values() {
        assert!(toml::from_str::<FilterConfig>("q_typo = 1.0\n").is_err());
        let bad = [
            FilterConfig {
                q_pos: f64::NAN,
                ..Default::default()
            },
            FilterConfig {
                q_w: -1.0,
                ..Default::default()
            },
            FilterConfig {
                sigma_rot_deg: 0.0,
                ..Default::default()
            },
            FilterConfig {
                sigma_pos_m: f64::NAN,
                ..Default::default()
            },
            FilterConfig {
                gate_mahalanobis2: Some(f64::NAN),
                ..Default::default()
            },
            FilterConfig {
                initial_sigma_w_degps: f64::INFINITY,
                ..Default::default()
            },
            FilterConfig {
                q_w_sensor: f64::NAN,
                ..Default::default()
            },
            FilterConfig {
                initial_sigma_w_sensor_degps: 0.0,
                ..Default::default()
            },
        ];
        for c in bad {
            assert!(c.validate().is_err(), "{c:?} should be rejected");
        }
        FilterConfig {
            gate_mahalanobis2: None,
            ..Default::default()
        }
        .validate()
        .unwrap();
    }
}
