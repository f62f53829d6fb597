//! Detection model of seed 002 §3.2: probability of detection from the
//! signal-to-noise ratio (Eq. 4-9), with the parameters of Table 1.

use crate::error::SimError;

/// Planck constant (J s), CODATA 2018 exact value.
pub const PLANCK_J_S: f64 = 6.626_070_15e-34;
/// Boltzmann constant (J/K), CODATA 2018 exact value.
pub const BOLTZMANN_J_PER_K: f64 = 1.380_649e-23;
/// Elementary charge (C), CODATA 2018 exact value.
pub const ELECTRON_CHARGE_C: f64 = 1.602_176_634e-19;
/// Speed of light in vacuum (m/s).
pub const SPEED_OF_LIGHT_M_S: f64 = 299_792_458.0;

/// Lidar transmitter, receiver and detector parameters (seed 002 Table 1).
#[derive(Debug, Clone, PartialEq)]
pub struct DetectionParams {
    /// λ, laser wavelength (m): 1540 nm.
    pub wavelength_m: f64,
    /// Pw_TRAN, average transmitted laser power (W): 1 mW.
    pub avg_power_w: f64,
    /// τ_W, pulse width (s): 1 ns.
    pub pulse_width_s: f64,
    /// PRF, pulse repetition frequency (Hz): 10 kHz.
    pub prf_hz: f64,
    /// D, receiver aperture diameter (m): 2.5 cm.
    pub aperture_m: f64,
    /// τ_O, optical band-pass filter transmittance: 0.3898.
    pub filter_transmittance: f64,
    /// η, detector quantum efficiency: 0.7247.
    pub quantum_efficiency: f64,
    /// G_APD, avalanche photodiode gain: 10.
    pub apd_gain: f64,
    /// Ca, detector circuit capacitance (F): 1.5 pF.
    pub capacitance_f: f64,
    /// Temp, detector temperature (K): 273.15 K.
    pub temperature_k: f64,
    /// i_D, dark current mean intensity (A): 150 nA.
    pub dark_current_a: f64,
    /// Pw_BACK, background (solar) power collected by the receiver (W).
    ///
    /// Default 5e-11 W: sunlit Lambertian surface of reflectance 0.5 under
    /// the AM0 spectral irradiance at 1540 nm (≈ 0.26 W m⁻² nm⁻¹, ASTM E490)
    /// over the 24 nm filter band (6.2 W/m², radiance ρE/π ≈ 1 W m⁻² sr⁻¹),
    /// seen through the 2.5 cm aperture (4.9e-4 m²) within the 0.02°
    /// instantaneous field of view (9.6e-8 sr): 4.7e-11 W. It yields about
    /// 0.1 photoelectron per pulse, negligible next to the thermal noise
    /// (Eq. 7, ≈ 2.2e5 electrons²), as expected for a 1 ns gate.
    pub background_power_w: f64,
    /// P_FA, probability of false alarm: 1e-4.
    pub false_alarm_probability: f64,
}

impl Default for DetectionParams {
    fn default() -> Self {
        Self::seed002()
    }
}

impl DetectionParams {
    /// The values of seed 002 Table 1.
    pub fn seed002() -> Self {
        DetectionParams {
            wavelength_m: 1540e-9,
            avg_power_w: 1e-3,
            pulse_width_s: 1e-9,
            prf_hz: 10e3,
            aperture_m: 0.025,
            filter_transmittance: 0.3898,
            quantum_efficiency: 0.7247,
            apd_gain: 10.0,
            capacitance_f: 1.5e-12,
            temperature_k: 273.15,
            dark_current_a: 150e-9,
            background_power_w: 5e-11,
            false_alarm_probability: 1e-4,
        }
    }

    /// The Livox Mid-40 receiver: seed 002's detector chain (Table 1) with
    /// the transmitted power scaled so that the datasheet's detection range
    /// holds, P_D = 0.5 for a Lambertian surface of 10 % reflectance at
    /// 90 m. The datasheet's other point (80 % at 260 m) has nearly the same
    /// return factor (1.18e-5 against 1.23e-5 m⁻²), so one scale fits both.
    ///
    /// Why not seed 002's values as they are: that space receiver (1 mW,
    /// 2.5 cm aperture) is about 35 times less sensitive than a Mid-40, and
    /// it made the oblique golden MLI of the end faces vanish entirely at
    /// 15 m (down to 900 points per 1 s scan, where the EPOS recordings of
    /// seed 000 §4.3 never had fewer than 8,000).
    pub fn livox_mid40() -> Self {
        let mut params = Self::seed002();
        let model = params.model();
        let snr_at_half = model.half_log_inv_pfa * model.half_log_inv_pfa - 0.5; // Eq. (4) with P_D = ½
        let return_factor = MID40_RANGE_REFLECTANCE / (MID40_RANGE_M * MID40_RANGE_M);
        params.avg_power_w *= snr_at_half / model.snr(return_factor);
        params
    }

    /// Rejects NaN, infinite and non-positive values (and P_FA outside (0, 1)).
    pub fn validate(&self) -> Result<(), SimError> {
        let positive = [
            ("detection.wavelength_m", self.wavelength_m),
            ("detection.avg_power_w", self.avg_power_w),
            ("detection.pulse_width_s", self.pulse_width_s),
            ("detection.prf_hz", self.prf_hz),
            ("detection.aperture_m", self.aperture_m),
            ("detection.filter_transmittance", self.filter_transmittance),
            ("detection.quantum_efficiency", self.quantum_efficiency),
            ("detection.apd_gain", self.apd_gain),
            ("detection.capacitance_f", self.capacitance_f),
            ("detection.temperature_k", self.temperature_k),
        ];
        for (field, value) in positive {
            crate::error::check_positive(field, value)?;
        }
        for (field, value) in [
            ("detection.dark_current_a", self.dark_current_a),
            ("detection.background_power_w", self.background_power_w),
        ] {
            if !value.is_finite() || value < 0.0 {
                return Err(SimError::InvalidConfig {
                    field,
                    value,
                    reason: "must be finite and >= 0",
                });
            }
        }
        let pfa = self.false_alarm_probability;
        if !(pfa > 0.0 && pfa < 1.0) {
            return Err(SimError::InvalidConfig {
                field: "detection.false_alarm_probability",
                value: pfa,
                reason: "must be in (0, 1)",
            });
        }
        Ok(())
    }

    /// Precomputes the range-independent factors of Eq. (5)-(9).
    pub fn model(&self) -> DetectionModel {
        let photon_energy = PLANCK_J_S * SPEED_OF_LIGHT_M_S / self.wavelength_m; // h ν
        // Eq. (6) without ρ_T cos θ / R²: peak power × D²/4 × τ_O.
        let peak_power = self.avg_power_w / (self.prf_hz * self.pulse_width_s);
        let power_per_unit_return =
            peak_power * self.aperture_m * self.aperture_m / 4.0 * self.filter_transmittance;
        // Eq. (5), times the APD gain.
        let signal_electrons_per_unit_return =
            self.apd_gain * self.quantum_efficiency * power_per_unit_return * self.pulse_width_s
                / photon_energy;
        // Eq. (7).
        let thermal_variance = BOLTZMANN_J_PER_K * self.temperature_k * self.capacitance_f
            / (ELECTRON_CHARGE_C * ELECTRON_CHARGE_C);
        // Eq. (8): solar background plus dark current (i_D τ_W / q_e electrons), times the APD gain.
        let background = self.quantum_efficiency
            * self.filter_transmittance
            * self.background_power_w
            * self.pulse_width_s
            / photon_energy
            + self.dark_current_a * self.pulse_width_s / ELECTRON_CHARGE_C;
        DetectionModel {
            signal_electrons_per_unit_return,
            noise_sigma: (thermal_variance + self.apd_gain * background).sqrt(),
            half_log_inv_pfa: 0.5 * (1.0 / self.false_alarm_probability).ln(),
        }
    }
}

/// Livox Mid-40 datasheet: detection range (m) for a 10 % reflective target.
pub const MID40_RANGE_M: f64 = 90.0;
/// Reflectance of the datasheet's detection-range figure.
pub const MID40_RANGE_REFLECTANCE: f64 = 0.1;

/// Precomputed detection model: SNR and P_D of one echo.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetectionModel {
    signal_electrons_per_unit_return: f64,
    noise_sigma: f64,
    half_log_inv_pfa: f64,
}

impl DetectionModel {
    /// SNR of Eq. (9) for a received return factor `ρ_T cos θ / R²` (m⁻²).
    ///
    /// The simulator passes the Phong generalisation `Σ ρ_T f_Phong / r²`
    /// of the beam (seed 004 Eq. 17), which equals `ρ_T cos θ / R²` of
    /// Eq. (6) for a Lambertian surface (k_d = 1).
    #[inline]
    pub fn snr(&self, return_factor_per_m2: f64) -> f64 {
        self.signal_electrons_per_unit_return * return_factor_per_m2.max(0.0) / self.noise_sigma
    }

    /// Probability of detection of Eq. (4):
    /// `P_D = ½ {1 + erf[(½ + SNR)^½ - ½ ln(1/P_FA)]}`.
    #[inline]
    pub fn probability(&self, snr: f64) -> f64 {
        0.5 * (1.0 + erf((0.5 + snr.max(0.0)).sqrt() - self.half_log_inv_pfa))
    }
}

/// Error function, Abramowitz & Stegun 7.1.26 (absolute error < 1.5e-7).
pub fn erf(x: f64) -> f64 {
    let sign = x.signum();
    let x = x.abs();
    let t = 1.0 / (1.0 + 0.327_591_1 * x);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    sign * (1.0 - poly * (-x * x).exp())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mid40_receiver_meets_its_datasheet_ranges() {
        let m = DetectionParams::livox_mid40().model();
        let p = |reflectance: f64, range: f64| m.probability(m.snr(reflectance / (range * range)));
        assert!((p(0.1, 90.0) - 0.5).abs() < 1e-3);
        assert!((p(0.8, 260.0) - 0.5).abs() < 0.1);
        assert!(p(0.1, 40.0) > 0.999 && p(0.1, 200.0) < 0.01);
    }

    #[test]
    fn erf_matches_reference_values() {
        for (x, e) in [
            (0.0, 0.0),
            (0.5, 0.520_499_877_8),
            (1.0, 0.842_700_792_9),
            (2.0, 0.995_322_265),
            (-1.0, -0.842_700_792_9),
        ] {
            assert!((erf(x) - e).abs() < 2e-7, "erf({x})");
        }
    }

    #[test]
    fn detection_probability_is_monotonic_from_zero_to_one() {
        let m = DetectionParams::seed002().model();
        assert!(m.probability(0.0) < 1e-6, "{}", m.probability(0.0));
        assert!(m.probability(1e4) > 1.0 - 1e-9);
        let mut last = 0.0;
        for k in 0..2000 {
            let p = m.probability(k as f64 * 0.05);
            assert!(
                p >= last - 1e-12,
                "not monotonic at SNR {}",
                k as f64 * 0.05
            );
            last = p;
        }
        // P_D = 1/2 where sqrt(1/2 + SNR) = ½ ln(1/P_FA).
        let snr_half = (0.5 * (1e4f64).ln()).powi(2) - 0.5;
        assert!((m.probability(snr_half) - 0.5).abs() < 1e-6);
    }

    #[test]
    fn snr_scales_with_the_return_and_is_large_at_10_m() {
        let m = DetectionParams::seed002().model();
        // Lambertian ρ = 0.5 at normal incidence, 10 m.
        let snr10 = m.snr(0.5 / 100.0);
        assert!(snr10 > 1000.0 && snr10 < 10_000.0, "{snr10}");
        assert!((m.snr(0.5 / 400.0) - snr10 / 4.0).abs() < 1e-9 * snr10);
        assert!(m.probability(snr10) > 0.999_999);
        // Grazing incidence on a dark surface is hard to detect.
        assert!(m.probability(m.snr(0.175 * 0.005 / 100.0)) < 0.05);
    }

    #[test]
    fn validation_rejects_nan_and_bad_pfa() {
        let mut p = DetectionParams::seed002();
        p.aperture_m = f64::NAN;
        assert!(p.validate().is_err());
        let mut p = DetectionParams::seed002();
        p.false_alarm_probability = 1.0;
        assert!(p.validate().is_err());
        assert!(DetectionParams::seed002().validate().is_ok());
    }
}
