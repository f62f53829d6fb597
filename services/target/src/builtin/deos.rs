//! A DEOS-like client satellite, after the EPOS mockup of seed 004 (§III.C.4, Fig. 5, Fig. 6)
//! and the rendezvous geometry of seed 000 §4.3.
//!
//! # Body frame
//! Origin at the centre of the hexagonal main body, taken as the centre of mass (the main
//! body carries nearly all the mass; the tower and bars are light). `x` is the prism axis,
//! the "roll" axis of seed 004 about which the ±120° symmetry holds; the tower is on the +x
//! end. `y` points to hexagon vertex 0, `z = x × y`.
//!
//! # Geometry (m)
//! - Main body: right hexagonal prism along x, circumradius 0.9 (apothem 0.779), x in
//!   −1.0..+1.0. Hexagon vertex `k` (k = 0..5) at `(y, z) = 0.9 (cos 60°k, sin 60°k)`.
//! - Three bars: square section 0.08 × 0.08, 1.6 long (x in −0.8..+0.8), parallel to x,
//!   along the prism edges of vertices 0, 2 and 4 (alternate edges), one face touching the
//!   edge and the section centred on the radial line at radius 0.94. They are the
//!   "distinctive features" of seed 004 §III.C.4 that reduce the hexagon's six-fold
//!   symmetry to three-fold.
//! - Tower: cylinder (24-sided prism) of radius 0.12, from the +x face (x = 1.0) to
//!   x = 1.45, capped by a tip of radius 0.05 from x = 1.45 to 1.6 (the "tip of the
//!   satellite's tower" of seed 004 §IV.A).
//!
//! The tower tip is 1.6 m from the centre of mass, so at a 3 m centre-of-mass distance the
//! nearest surface is about 1.4–1.5 m away, as reported for the EPOS rendezvous (seed 000
//! §4.3). The bounding radius is that of the tip's rim, √(1.6² + 0.05²) ≈ 1.6008 m.
//!
//! # Materials
//! Seed 004 §IV.B splits the mockup into structure, solar panels and golden MLI (Table I
//! ranges). Choices here: solar panels body-mounted flush on all six side faces (which keeps
//! the prism's geometric symmetry, so only the bars break the 60° symmetry), MLI on both end
//! faces (seed 004 Fig. 6: the tower stands on a planar MLI-covered surface), structure for
//! bars and tower. Reflectance ρ for the seed-002 detection model: structure 0.6 (seed 002
//! mean of degraded surfaces), solar panel 0.175 (seed 002 solar cell cover), MLI 0.3 (see
//! [`crate::material::MLI_REFLECTANCE`]).
//!
//! # Symmetry
//! `{I, Rx(+120°), Rx(−120°)}` (seed 004 Fig. 5 and Eq. (14)); Rx(±60°) and Rx(180°) map the
//! bars onto empty edges and are not symmetries.

use std::f64::consts::PI;

use nalgebra::{Rotation3, Vector3};

use crate::error::TargetError;
use crate::material::{
    MEAN_REFLECTANCE, MLI_REFLECTANCE, Material, MaterialClass, MaterialId, SOLAR_CELL_REFLECTANCE,
};
use crate::mesh::Mesh;
use crate::shapes::regular_prism_x;
use crate::target::Target;

/// Material id of structure (bars, tower).
pub const STRUCTURE: MaterialId = 0;
/// Material id of the solar panels (side faces).
pub const SOLAR_PANEL: MaterialId = 1;
/// Material id of the MLI (end faces).
pub const MLI: MaterialId = 2;

/// Hexagon circumradius (m).
pub const BODY_CIRCUMRADIUS: f64 = 0.9;
/// Main body half length along x (m).
pub const BODY_HALF_LENGTH: f64 = 1.0;
/// Bar cross-section side (m).
pub const BAR_SIDE: f64 = 0.08;
/// Bar half length along x (m).
pub const BAR_HALF_LENGTH: f64 = 0.8;
/// Tower radius (m) and top x (m).
pub const TOWER: (f64, f64) = (0.12, 1.45);
/// Tip radius (m) and top x (m).
pub const TIP: (f64, f64) = (0.05, 1.6);
/// Number of sides of the polygonal tower and tip (multiple of 6, so the cylinders share the
/// hexagon's symmetries).
pub const CYLINDER_SIDES: u32 = 24;

/// The symmetry group: identity, Rx(+120°), Rx(−120°).
pub fn symmetries() -> Vec<Rotation3<f64>> {
    [0.0, 2.0 * PI / 3.0, -2.0 * PI / 3.0]
        .iter()
        .map(|&a| Rotation3::from_axis_angle(&Vector3::x_axis(), a))
        .collect()
}

/// The bar along the prism edge of hexagon vertex `k`.
fn bar(k: u32) -> Result<Mesh, TargetError> {
    let angle = f64::from(k) * PI / 3.0;
    let roll = Rotation3::from_axis_angle(&Vector3::x_axis(), angle);
    // In the rolled frame the vertex is on +y; the bar's inner face touches it.
    let center = roll * Vector3::new(0.0, BODY_CIRCUMRADIUS + 0.5 * BAR_SIDE, 0.0);
    let half = Vector3::new(BAR_HALF_LENGTH, 0.5 * BAR_SIDE, 0.5 * BAR_SIDE);
    Mesh::try_cuboid(center, half, roll, STRUCTURE)
}

/// Builds the DEOS-like target (see the module documentation).
pub fn target() -> Result<Target, TargetError> {
    let body = regular_prism_x(
        6,
        BODY_CIRCUMRADIUS,
        -BODY_HALF_LENGTH,
        BODY_HALF_LENGTH,
        0.0,
        SOLAR_PANEL,
        MLI,
    )?;
    let tower = regular_prism_x(
        CYLINDER_SIDES,
        TOWER.0,
        BODY_HALF_LENGTH,
        TOWER.1,
        0.0,
        STRUCTURE,
        STRUCTURE,
    )?;
    let tip = regular_prism_x(
        CYLINDER_SIDES,
        TIP.0,
        TOWER.1,
        TIP.1,
        0.0,
        STRUCTURE,
        STRUCTURE,
    )?;
    let mesh = Mesh::merged(&[body, bar(0)?, bar(2)?, bar(4)?, tower, tip])?;
    let materials = vec![
        Material::of_class("structure", MaterialClass::Structure, MEAN_REFLECTANCE),
        Material::of_class(
            "solar panel",
            MaterialClass::SolarPanel,
            SOLAR_CELL_REFLECTANCE,
        ),
        Material::of_class("golden MLI", MaterialClass::Mli, MLI_REFLECTANCE),
    ];
    Target::new("deos", mesh, materials, symmetries())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin::symmetry_check::max_symmetry_error;

    #[test]
    fn deos_dimensions_and_materials() {
        let t = target().unwrap();
        assert_eq!(t.name(), "deos");
        let expected_r = (TIP.1 * TIP.1 + TIP.0 * TIP.0).sqrt();
        assert!((t.bounding_radius() - expected_r).abs() < 1e-9);
        assert!((t.bounding_radius() - 1.6008).abs() < 1e-4);
        // 24 (hexagon) + 3 x 12 (bars) + 2 x 4 x 24 (tower, tip).
        assert_eq!(t.mesh().triangle_count(), 24 + 36 + 192);
        let m = t.materials();
        assert_eq!(m[usize::from(MLI)].kd_range, [1e-3, 1e-2]);
        assert_eq!(m[usize::from(MLI)].eta_range, [25.0, 75.0]);
        assert_eq!(m[usize::from(SOLAR_PANEL)].kd_range, [1e-2, 1e-1]);
        assert_eq!(m[usize::from(STRUCTURE)].eta_range, [0.5, 5.0]);
        // Rays: side face is solar panel at the apothem, end face -x is MLI, tower tip on +x.
        let apothem = BODY_CIRCUMRADIUS * (PI / 6.0).cos();
        let hit = t
            .cast_ray(&Vector3::new(0.1, 0.05, -5.0), &Vector3::z(), 10.0)
            .unwrap();
        assert_eq!(hit.material, SOLAR_PANEL);
        assert!((hit.distance - (5.0 - apothem)).abs() < 1e-9);
        let hit = t
            .cast_ray(&Vector3::new(-5.0, 0.3, 0.2), &Vector3::x(), 10.0)
            .unwrap();
        assert_eq!(hit.material, MLI);
        assert!((hit.distance - 4.0).abs() < 1e-9);
        let hit = t
            .cast_ray(&Vector3::new(3.0, 0.01, 0.02), &-Vector3::x(), 10.0)
            .unwrap();
        assert_eq!(hit.material, STRUCTURE);
        assert!((hit.distance - 1.4).abs() < 1e-9);
        let hit = t
            .cast_ray(&Vector3::new(3.0, 0.5, 0.03), &-Vector3::x(), 10.0)
            .unwrap();
        assert_eq!(hit.material, MLI);
        assert!((hit.distance - 2.0).abs() < 1e-9);
        // A bar on the edge of vertex 0 (+y), seen from +y.
        let hit = t
            .cast_ray(&Vector3::new(0.1, 5.0, 0.01), &-Vector3::y(), 10.0)
            .unwrap();
        assert_eq!(hit.material, STRUCTURE);
        assert!((hit.distance - (5.0 - BODY_CIRCUMRADIUS - BAR_SIDE)).abs() < 1e-9);
        // No bar on the edge of vertex 3 (-y): the ray reaches the side face next to that
        // edge, which slopes at 30° from the y axis.
        let z = 0.01;
        let hit = t
            .cast_ray(&Vector3::new(0.1, -5.0, z), &Vector3::y(), 10.0)
            .unwrap();
        assert_eq!(hit.material, SOLAR_PANEL);
        let y_face = -BODY_CIRCUMRADIUS + z * (PI / 6.0).tan();
        assert!((hit.distance - (5.0 + y_face)).abs() < 1e-9);
    }

    #[test]
    fn deos_symmetries_map_the_mesh_onto_itself() {
        let t = target().unwrap();
        assert_eq!(t.symmetries().len(), 3);
        for s in t.symmetries() {
            let err = max_symmetry_error(&t, s, 0.02);
            println!(
                "deos symmetry Rx({:.0}°): max error {err:.2e} m",
                s.angle().to_degrees()
            );
            assert!(err < 1e-3, "{s:?}: {err}");
        }
        for deg in [60.0f64, 180.0, -60.0] {
            let s = Rotation3::from_axis_angle(&Vector3::x_axis(), deg.to_radians());
            let err = max_symmetry_error(&t, &s, 0.02);
            println!("deos non-symmetry Rx({deg}°): max error {err:.3} m");
            assert!(err > 0.03, "Rx({deg}) should not be a symmetry: {err}");
        }
    }

    #[test]
    fn deos_surface_sample_at_1_5_cm() {
        let t = target().unwrap();
        let pts = t.sample_surface(0.015, 42);
        let expected = t.mesh().surface_area() / (0.015 * 0.015);
        assert!(pts.len() > 20_000);
        assert!((pts.len() as f64 - expected).abs() / expected < 0.02);
        println!(
            "deos: area {:.3} m², {} model points at 1.5 cm",
            t.mesh().surface_area(),
            pts.len()
        );
    }
}
