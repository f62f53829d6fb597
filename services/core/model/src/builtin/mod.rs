//! Built-in target models.
//!
//! - [`envisat`]: five-cuboid ENVISAT of seed 002 §3.1 (no symmetry).
//! - [`deos`]: DEOS-like hexagonal client of seed 004 §III.C.4 (±120° roll symmetry).

pub mod deos;
pub mod envisat;

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
