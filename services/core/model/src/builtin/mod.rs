//! Built-in target models.
//!
//! - [`envisat`]: five-cuboid ENVISAT of seed 002 §3.1 (no symmetry).
//! - [`deos`]: DEOS-like hexagonal client of seed 004 §III.C.4 (±120° roll symmetry).

pub mod deos;
pub mod envisat;

use crate::error::TargetError;
use crate::target::Target;
use std::path::Path;

/// Built-in targets by name. (These constructors live here, beside the
/// targets they build, so the target module does not reach back into the
/// built-in ones.)
impl Target {
    /// A built-in target by name (see [`Target::BUILTIN`]): `"envisat"` (seed 002 §3.1) or
    /// `"deos"` (seed 004 §III.C.4).
    pub fn builtin(name: &str) -> Result<Target, TargetError> {
        match name {
            "envisat" => envisat::target(),
            "deos" => deos::target(),
            other => Err(TargetError::UnknownBuiltin(other.to_owned())),
        }
    }

    /// A built-in target if `spec` is one of [`Target::BUILTIN`], otherwise a mesh file path
    /// (see [`Target::load`]). `scale` multiplies the coordinates in both cases (use 1.0 for
    /// built-in targets at their true size).
    pub fn resolve(spec: &str, scale: f64) -> Result<Target, TargetError> {
        if Target::BUILTIN.contains(&spec) {
            Target::builtin(spec)?.scaled(spec, scale)
        } else {
            Target::load(Path::new(spec), scale)
        }
    }
}

#[cfg(test)]
pub(crate) mod symmetry_check {
    use nalgebra::Rotation3;

    use crate::target::Target;

    /// Largest distance (m) from a rotated surface sample `S p` to the mesh surface: zero
    /// (to f32 precision) when `S` maps the mesh onto itself.
    pub(crate) fn max_symmetry_error(t: &Target, s: &Rotation3<f64>, spacing_m: f64) -> f64 {
        let pts = t.sample_surface(spacing_m, 5);
        assert!(pts.len() > 1000, "too few samples: {}", pts.len());
        pts.iter()
            .map(|p| t.mesh().distance_to_surface(&(s * p)))
            .fold(0.0, f64::max)
    }
}
