//! ENVISAT as five cuboids, after seed 002 §3.1 (Opromolla et al. 2015, Fig. 3).
//!
//! # Body frame
//! As in seed 002: origin at the geometric centre of the main body (the "TRF"; taken as the
//! centre of mass, the real one being unknown), `x` along the main body's long axis (ESA's
//! Xs, normal to the orbit plane in flight, solar array on the −x end), `y` along the
//! ASAR antenna's 10 m length (ESA's Ys, close to the velocity), `z` toward the antenna side
//! (ESA's Zs, Earth-pointing).
//!
//! # Dimensions (m) and their sources
//! ESA's Envisat pages give a launch envelope of 10.5 m length × 4.57 m diameter and an
//! in-orbit envelope of 26 m × 10 m × 5 m; ESA education material gives 10 m × 4 m × 4 m
//! stowed; the solar array is 14 m × 5 m (ESA press material quotes a "15 m array" and a
//! 25 m span), the ASAR antenna 10 m × 1.3 m, mounted on the Earth-facing side of the
//! payload module with its long side along-track. The cuboids below reproduce the
//! 26 × 10 × 5 m envelope:
//!
//! | part | size x × y × z | centre | material |
//! |------|----------------|--------|----------|
//! | main body | 10.0 × 4.0 × 4.0 | (0, 0, 0) | steel |
//! | solar array boom (appendage) | 2.0 × 0.3 × 0.3 | (−6, 0, 0) | steel |
//! | solar array | 14.0 × 5.0 × 0.1 | (−14, 0, 0) | solar cell |
//! | ASAR support (appendage) | 1.0 × 1.0 × 0.6 | (3.0, 0, 2.3) | steel |
//! | ASAR antenna | 1.3 × 10.0 × 0.15 | (3.0, 0, 2.675) | aluminium |
//!
//! - main body: 10 m long (launch length 10.5 m less adapter), 4 m across (stowed
//!   10 × 4 × 4 m; a square section of 4 m is the simplest box near the 4.57 m envelope);
//! - solar array: 14 m × 5 m, a flat panel 0.1 m thick in the x-y plane on the −x end, on a
//!   2 m boom: x spans −21..+5 m, the 26 m in-orbit length;
//! - ASAR antenna: 10 m × 1.3 m, 0.15 m thick, along y, held 0.6 m off the +z face near the
//!   +x (payload) end by a 1 m × 1 m support: y spans 10 m, z spans −2..+2.75 m (≈ 5 m).
//!
//! The envelope is therefore 26 × 10 × 4.75 m; the bounding radius (largest vertex distance
//! from the origin) is that of the solar array's far corners, √(21² + 2.5² + 0.05²) ≈
//! 21.148 m.
//!
//! # Materials (seed 002 §3.1)
//! Steel ρ = 0.733 (main body, both appendages), solar-cell fused-silica cover ρ = 0.175
//! (solar array), aluminium ρ = 0.969 (ASAR antenna). Phong ranges from seed 004 Table I by
//! class (aluminium uses the structure ranges).
//!
//! # Symmetry
//! Identity only: the solar array sits on one end of the long axis and the antenna on one
//! side, so no proper rotation other than the identity maps the model onto itself (a
//! half-turn about x would move the antenna from +z to −z, one about z or y would swap the
//! array end, and so on).

use nalgebra::{Rotation3, Vector3};

use crate::error::TargetError;
use crate::material::{
    ALUMINIUM_REFLECTANCE, Material, MaterialClass, MaterialId, SOLAR_CELL_REFLECTANCE,
    STEEL_REFLECTANCE,
};
use crate::mesh::Mesh;
use crate::target::Target;

/// Material id of steel (main body and appendages).
pub const STEEL: MaterialId = 0;
/// Material id of the solar cell cover (solar array).
pub const SOLAR_CELL: MaterialId = 1;
/// Material id of aluminium (ASAR antenna).
pub const ALUMINIUM: MaterialId = 2;

/// One cuboid part: name, centre (m), full size (m), material.
pub struct Part {
    /// Name of the part.
    pub name: &'static str,
    /// Centre in the body frame (m).
    pub center: [f64; 3],
    /// Full size along x, y, z (m).
    pub size: [f64; 3],
    /// Material id.
    pub material: MaterialId,
}

/// The five cuboids of the model, in mesh face order (12 faces each).
pub const PARTS: [Part; 5] = [
    Part {
        name: "main body",
        center: [0.0, 0.0, 0.0],
        size: [10.0, 4.0, 4.0],
        material: STEEL,
    },
    Part {
        name: "solar array boom",
        center: [-6.0, 0.0, 0.0],
        size: [2.0, 0.3, 0.3],
        material: STEEL,
    },
    Part {
        name: "solar array",
        center: [-14.0, 0.0, 0.0],
        size: [14.0, 5.0, 0.1],
        material: SOLAR_CELL,
    },
    Part {
        name: "ASAR support",
        center: [3.0, 0.0, 2.3],
        size: [1.0, 1.0, 0.6],
        material: STEEL,
    },
    Part {
        name: "ASAR antenna",
        center: [3.0, 0.0, 2.675],
        size: [1.3, 10.0, 0.15],
        material: ALUMINIUM,
    },
];

/// Builds the ENVISAT target (see the module documentation).
pub fn target() -> Result<Target, TargetError> {
    let parts: Vec<Mesh> = PARTS
        .iter()
        .map(|p| {
            Mesh::try_cuboid(
                Vector3::from(p.center),
                Vector3::from(p.size) * 0.5,
                Rotation3::identity(),
                p.material,
            )
        })
        .collect::<Result<_, _>>()?;
    let mesh = Mesh::merged(&parts)?;
    let materials = vec![
        Material::of_class("steel", MaterialClass::Structure, STEEL_REFLECTANCE),
        Material::of_class(
            "solar cell fused silica",
            MaterialClass::SolarPanel,
            SOLAR_CELL_REFLECTANCE,
        ),
        Material::of_class("aluminium", MaterialClass::Aluminium, ALUMINIUM_REFLECTANCE),
    ];
    Target::new("envisat", mesh, materials, vec![Rotation3::identity()])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin::symmetry_check::max_symmetry_error;

    #[test]
    fn envisat_dimensions_and_materials() {
        let t = target().unwrap();
        assert_eq!(t.name(), "envisat");
        assert_eq!(t.mesh().triangle_count(), 60);
        let expected_r = (21.0f64.powi(2) + 2.5f64.powi(2) + 0.05f64.powi(2)).sqrt();
        assert!((t.bounding_radius() - expected_r).abs() < 1e-9);
        // Envelope 26 x 10 x 4.75 m.
        let v = t.mesh().vertices();
        let span = |k: usize| {
            let (lo, hi) = v.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
                (lo.min(p[k]), hi.max(p[k]))
            });
            hi - lo
        };
        assert!((span(0) - 26.0).abs() < 1e-12);
        assert!((span(1) - 10.0).abs() < 1e-12);
        assert!((span(2) - 4.75).abs() < 1e-12);
        // Materials per face, in part order.
        for (i, p) in PARTS.iter().enumerate() {
            assert!(
                t.mesh().face_materials()[12 * i..12 * (i + 1)]
                    .iter()
                    .all(|&m| m == p.material),
                "{}",
                p.name
            );
        }
        let m = t.materials();
        assert_eq!(m[usize::from(STEEL)].reflectance, 0.733);
        assert_eq!(m[usize::from(SOLAR_CELL)].reflectance, 0.175);
        assert_eq!(m[usize::from(ALUMINIUM)].reflectance, 0.969);
        assert_eq!(t.symmetries().len(), 1);
    }

    #[test]
    fn envisat_rays_see_the_right_parts() {
        let t = target().unwrap();
        // From +z above the antenna: aluminium at z = 2.75.
        let down = -Vector3::z();
        let hit = t
            .cast_ray(&Vector3::new(3.0, 4.0, 30.0), &down, 100.0)
            .unwrap();
        assert_eq!(hit.material, ALUMINIUM);
        assert!((hit.distance - 27.25).abs() < 1e-9);
        // Over the solar array: solar cell at z = 0.05.
        let hit = t
            .cast_ray(&Vector3::new(-15.0, 1.0, 30.0), &down, 100.0)
            .unwrap();
        assert_eq!(hit.material, SOLAR_CELL);
        assert!((hit.distance - 29.95).abs() < 1e-9);
        // Over the body, beside the antenna: steel at z = 2.
        let hit = t
            .cast_ray(&Vector3::new(-2.0, 1.0, 30.0), &down, 100.0)
            .unwrap();
        assert_eq!(hit.material, STEEL);
        assert!((hit.distance - 28.0).abs() < 1e-9);
    }

    #[test]
    fn envisat_has_no_rotational_symmetry() {
        let t = target().unwrap();
        assert!(max_symmetry_error(&t, &Rotation3::identity(), 0.2) < 1e-4);
        for (axis, angle) in [
            (Vector3::x_axis(), std::f64::consts::PI),
            (Vector3::y_axis(), std::f64::consts::PI),
            (Vector3::z_axis(), std::f64::consts::PI),
        ] {
            let s = Rotation3::from_axis_angle(&axis, angle);
            assert!(max_symmetry_error(&t, &s, 0.2) > 0.5);
        }
    }
}
