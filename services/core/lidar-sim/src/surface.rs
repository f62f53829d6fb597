//! Per-frame material draws (seed 004 §IV.B, domain randomisation): for each
//! material, `k_d` log-uniform and `η` uniform within its Table I range.

use crate::error::SimError;
use crate::optics::reflection_cone_half_angle;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use spacepose_model::Material;

/// Reflective properties of one surface for one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    /// ρ_T, reflection coefficient (seed 002 Eq. 6).
    pub reflectance: f64,
    /// k_d, diffuse coefficient (seed 004 Eq. 17); `k_s = 1 - k_d`.
    pub kd: f64,
    /// η, specular exponent (seed 004 Eq. 17).
    pub eta: f64,
    /// Half-angle of the reflection cone `sqrt(2/η)` (rad), precomputed.
    pub cone_half_angle: f64,
}

impl Surface {
    /// A Lambertian surface (`k_d = 1`, no specular lobe).
    pub fn lambertian(reflectance: f64) -> Self {
        Surface {
            reflectance,
            kd: 1.0,
            eta: 1.0,
            cone_half_angle: 0.0,
        }
    }

    /// One random draw within the ranges of `material`.
    pub fn draw(material: &Material, rng: &mut ChaCha8Rng) -> Self {
        let [k0, k1] = material.kd_range;
        let [e0, e1] = material.eta_range;
        let kd = if k1 > k0 {
            rng.random_range(k0.ln()..=k1.ln()).exp()
        } else {
            k0
        };
        let eta = if e1 > e0 {
            rng.random_range(e0..=e1)
        } else {
            e0
        };
        Surface {
            reflectance: material.reflectance,
            kd,
            eta,
            cone_half_angle: reflection_cone_half_angle(eta),
        }
    }
}

/// Checks that every material can be drawn: finite positive ordered ranges,
/// `k_d ≤ 1`, reflectance in [0, 1].
pub fn validate_materials(target_name: &str, materials: &[Material]) -> Result<(), SimError> {
    if materials.is_empty() {
        return Err(SimError::NoMaterial(target_name.to_owned()));
    }
    let bad = |reason| SimError::BadMaterial {
        target: target_name.to_owned(),
        materials: materials.len(),
        reason,
    };
    for m in materials {
        let ordered =
            |r: [f64; 2]| r[0].is_finite() && r[1].is_finite() && r[0] > 0.0 && r[0] <= r[1];
        if !ordered(m.kd_range) || m.kd_range[1] > 1.0 {
            return Err(bad("k_d range must be finite, ordered, within (0, 1]"));
        }
        if !ordered(m.eta_range) {
            return Err(bad("η range must be finite, positive and ordered"));
        }
        if !(0.0..=1.0).contains(&m.reflectance) {
            return Err(bad("reflectance must be in [0, 1]"));
        }
    }
    Ok(())
}

/// Draws the surfaces of one frame, indexed by `MaterialId`.
pub fn draw_surfaces(materials: &[Material], rng: &mut ChaCha8Rng) -> Vec<Surface> {
    materials.iter().map(|m| Surface::draw(m, rng)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use spacepose_model::MaterialClass;

    #[test]
    fn draws_stay_in_table_one_and_kd_is_log_uniform() {
        let mli = Material::of_class("mli", MaterialClass::Mli, 0.3);
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        let n = 20_000;
        let mut below_geometric_mean = 0;
        for _ in 0..n {
            let s = Surface::draw(&mli, &mut rng);
            assert!((1e-3..=1e-2).contains(&s.kd) && (25.0..=75.0).contains(&s.eta));
            assert!((s.cone_half_angle - (2.0 / s.eta).sqrt()).abs() < 1e-15);
            below_geometric_mean += (s.kd < (1e-3f64 * 1e-2).sqrt()) as usize;
        }
        // Log-uniform: half the draws below the geometric mean of the bounds.
        let frac = below_geometric_mean as f64 / n as f64;
        assert!((frac - 0.5).abs() < 0.02, "{frac}");
    }

    #[test]
    fn invalid_materials_are_rejected() {
        assert!(matches!(
            validate_materials("x", &[]),
            Err(SimError::NoMaterial(_))
        ));
        let mut m = Material::of_class("s", MaterialClass::Structure, 0.6);
        m.kd_range = [0.5, 2.0];
        assert!(validate_materials("x", &[m]).is_err());
        let mut m = Material::of_class("s", MaterialClass::Structure, 0.6);
        m.eta_range = [f64::NAN, 2.0];
        assert!(validate_materials("x", &[m]).is_err());
        assert!(validate_materials("x", &[Material::default_structure()]).is_ok());
    }
}
