//! Errors of the lidar simulator.

use thiserror::Error;

/// Everything that can go wrong when configuring the simulator.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SimError {
    /// A configuration value is NaN, infinite, non-positive where it must be
    /// positive, or out of its admissible range.
    #[error("invalid sensor configuration: {field} = {value} ({reason})")]
    InvalidConfig {
        /// Name of the offending field.
        field: &'static str,
        /// The rejected value.
        value: f64,
        /// Why it was rejected.
        reason: &'static str,
    },
    /// The scan pattern would produce no ray (or an absurd number of rays).
    #[error("scan pattern yields {rays} rays per frame (must be 1..={max})")]
    RayCount {
        /// Rays the configuration asks for.
        rays: f64,
        /// Upper bound accepted.
        max: usize,
    },
    /// The target has no material, so per-frame material draws are impossible.
    #[error("target `{0}` has no material")]
    NoMaterial(String),
    /// The truth state holds a NaN or infinite number.
    #[error("truth state is not finite (t = {0})")]
    NonFiniteTruth(f64),
    /// The world's departures from the model ([`crate::Mismatch`]) are
    /// invalid or the as-built target cannot be built.
    #[error("mismatch: {0}")]
    Mismatch(String),
    /// A material cannot be drawn, or a mesh face refers to a material the
    /// target does not define.
    #[error("target `{target}` ({materials} materials): {reason}")]
    BadMaterial {
        /// Target name.
        target: String,
        /// Number of materials of the target.
        materials: usize,
        /// What is wrong with it.
        reason: &'static str,
    },
}

/// Error unless `value` is finite and strictly positive.
pub(crate) fn check_positive(field: &'static str, value: f64) -> Result<(), SimError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(SimError::InvalidConfig {
            field,
            value,
            reason: "must be finite and > 0",
        })
    }
}
