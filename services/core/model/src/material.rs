//! Surface materials of target models.
//!
//! Each material carries the parameters of both lidar models of the project:
//! - `reflectance`: the reflection coefficient ρ_T of the detection model of seed 002
//!   (Eq. (6), lidar equation of a well-resolved Lambertian-like target);
//! - `kd_range`, `eta_range`: the domain-randomisation ranges of the Phong model of seed 004
//!   (Eq. (17), Table I): diffuse coefficient k_d (drawn on a log scale) and specular exponent η.

/// Index of a material in [`crate::Target::materials`].
pub type MaterialId = u16;

/// Kind of surface, following the three categories of seed 004 §IV.B plus the aluminium
/// SAR antenna of the ENVISAT model of seed 002 §3.1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MaterialClass {
    /// Structural elements (bars, frames, painted or bare metal such as steel).
    Structure,
    /// Solar cells behind their fused-silica cover glass.
    SolarPanel,
    /// Multi-layer insulation (golden MLI blanket).
    Mli,
    /// Bare, highly reflective aluminium (ENVISAT's ASAR antenna in seed 002).
    Aluminium,
}

/// Seed 004 Table I, structure: k_d range.
pub const STRUCTURE_KD: [f64; 2] = [0.1, 1.0];
/// Seed 004 Table I, structure: η range.
pub const STRUCTURE_ETA: [f64; 2] = [0.5, 5.0];
/// Seed 004 Table I, solar panel: k_d range.
pub const SOLAR_PANEL_KD: [f64; 2] = [1e-2, 1e-1];
/// Seed 004 Table I, solar panel: η range.
pub const SOLAR_PANEL_ETA: [f64; 2] = [5.0, 20.0];
/// Seed 004 Table I, MLI: k_d range.
pub const MLI_KD: [f64; 2] = [1e-3, 1e-2];
/// Seed 004 Table I, MLI: η range.
pub const MLI_ETA: [f64; 2] = [25.0, 75.0];

/// Seed 002 §3.1: mean reflection coefficient of degraded satellite surfaces.
pub const MEAN_REFLECTANCE: f64 = 0.6;
/// Seed 002 §3.1: aluminium (ENVISAT SAR antenna).
pub const ALUMINIUM_REFLECTANCE: f64 = 0.969;
/// Seed 002 §3.1: solar cell fused-silica cover (ENVISAT solar array).
pub const SOLAR_CELL_REFLECTANCE: f64 = 0.175;
/// Seed 002 §3.1: steel (ENVISAT main body and appendages).
pub const STEEL_REFLECTANCE: f64 = 0.733;
/// Diffuse backscatter coefficient assumed for golden MLI (not in the seeds, our choice):
/// MLI is almost a mirror (seed 004 Table I: k_d ≤ 1e-2, η ≥ 25), so little energy comes
/// straight back except near normal incidence; 0.3 sits between the solar cell cover (0.175)
/// and the degraded-surface mean (0.6) of seed 002.
pub const MLI_REFLECTANCE: f64 = 0.3;

/// A surface material (see the module documentation for the meaning of each field).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Human-readable name ("steel", "solar cell", ...).
    pub name: String,
    /// Kind of surface.
    pub class: MaterialClass,
    /// ρ_T of seed 002 Eq. (6), in [0, 1].
    pub reflectance: f64,
    /// Seed 004 Table I: range of the diffuse coefficient k_d (drawn log-uniformly).
    pub kd_range: [f64; 2],
    /// Seed 004 Table I: range of the specular exponent η.
    pub eta_range: [f64; 2],
}

impl Material {
    /// A material with the Table I ranges of its class.
    ///
    /// [`MaterialClass::Aluminium`] gets the structure ranges: Table I lumps all metallic
    /// structural elements into "structure".
    pub fn of_class(name: &str, class: MaterialClass, reflectance: f64) -> Material {
        let (kd_range, eta_range) = match class {
            MaterialClass::Structure | MaterialClass::Aluminium => (STRUCTURE_KD, STRUCTURE_ETA),
            MaterialClass::SolarPanel => (SOLAR_PANEL_KD, SOLAR_PANEL_ETA),
            MaterialClass::Mli => (MLI_KD, MLI_ETA),
        };
        Material {
            name: name.to_owned(),
            class,
            reflectance,
            kd_range,
            eta_range,
        }
    }

    /// Default material of loaded meshes: structure, ρ = 0.6 (seed 002 §3.1 mean).
    pub fn default_structure() -> Material {
        Material::of_class("structure", MaterialClass::Structure, MEAN_REFLECTANCE)
    }

    /// Checks that the reflectance is in [0, 1] and that both ranges are finite, positive and
    /// ordered; returns a description of the first problem.
    pub fn validate(&self) -> Result<(), String> {
        if !(0.0..=1.0).contains(&self.reflectance) {
            return Err(format!(
                "material '{}': reflectance {} not in [0, 1]",
                self.name, self.reflectance
            ));
        }
        for (what, r) in [("kd_range", self.kd_range), ("eta_range", self.eta_range)] {
            if !(r[0].is_finite() && r[1].is_finite() && r[0] > 0.0 && r[0] <= r[1]) {
                return Err(format!(
                    "material '{}': {what} {:?} is not a finite positive ordered range",
                    self.name, r
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn class_ranges_follow_table_one() {
        let m = Material::of_class("mli", MaterialClass::Mli, MLI_REFLECTANCE);
        assert_eq!(m.kd_range, [1e-3, 1e-2]);
        assert_eq!(m.eta_range, [25.0, 75.0]);
        let s = Material::of_class("panel", MaterialClass::SolarPanel, 0.175);
        assert_eq!(s.kd_range, [1e-2, 1e-1]);
        assert_eq!(s.eta_range, [5.0, 20.0]);
        let d = Material::default_structure();
        assert_eq!(d.class, MaterialClass::Structure);
        assert_eq!(d.reflectance, 0.6);
        assert_eq!(d.kd_range, [0.1, 1.0]);
        assert_eq!(d.eta_range, [0.5, 5.0]);
        assert!(d.validate().is_ok());
    }

    #[test]
    fn validate_rejects_bad_values() {
        let mut m = Material::default_structure();
        m.reflectance = f64::NAN;
        assert!(m.validate().is_err());
        let mut m = Material::default_structure();
        m.kd_range = [0.5, 0.1];
        assert!(m.validate().is_err());
    }
}
