//! The parts a generated spacecraft is assembled from, each built along
//! its own x axis and then placed: boxes, prisms and cones (over regular
//! polygons), and dish reflectors.

use crate::error::TargetError;
use crate::material::MaterialId;
use crate::mesh::Mesh;
use crate::shapes::frustum_x;
use nalgebra::{Rotation3, Vector3};
use std::f64::consts::PI;

/// Material ids of every generated target (see [`super::materials`]).
pub const MLI: MaterialId = 0;
/// Solar cells of the wings.
pub const SOLAR: MaterialId = 1;
/// Structure: masts, booms, yokes, boxes, nozzles.
pub const STRUCTURE: MaterialId = 2;
/// Bare aluminium: dish reflectors.
pub const ALUMINIUM: MaterialId = 3;

/// The rotation taking +x to the unit direction `d` (a half-turn about z
/// when `d` is −x, where the shortest arc is not unique).
pub fn x_to(d: &Vector3<f64>) -> Rotation3<f64> {
    Rotation3::rotation_between(&Vector3::x(), d)
        .unwrap_or_else(|| Rotation3::from_axis_angle(&Vector3::z_axis(), PI))
}

/// A unit direction in the y-z plane at angle `phi` from +y toward +z.
pub fn radial(phi: f64) -> Vector3<f64> {
    Vector3::new(0.0, phi.cos(), phi.sin())
}

/// A box of full size `size` (along its own x, y, z), turned by `rotation`
/// and centred at `center`.
pub fn cuboid(
    center: Vector3<f64>,
    size: Vector3<f64>,
    rotation: Rotation3<f64>,
    material: MaterialId,
) -> Result<Mesh, TargetError> {
    Mesh::try_cuboid(center, size * 0.5, rotation, material)
}

/// A frustum of `sides` sides with radii `radii_m` running `length_m`
/// from `base` along the unit direction `axis`; `phase_rad` turns its
/// polygon about its own axis.
pub fn frustum(
    base: Vector3<f64>,
    axis: &Vector3<f64>,
    length_m: f64,
    radii_m: [f64; 2],
    sides: u32,
    phase_rad: f64,
    material: MaterialId,
) -> Result<Mesh, TargetError> {
    frustum_x(
        sides,
        radii_m,
        [0.0, length_m],
        phase_rad,
        material,
        material,
    )?
    .transformed(&x_to(axis), &base)
}

/// A dish reflector: an open paraboloid of rim radius `radius_m` and depth
/// `depth_m`, its vertex at `vertex` and opening along the unit `axis`;
/// 4 rings of 24 segments.
pub fn dish(
    vertex: Vector3<f64>,
    axis: &Vector3<f64>,
    radius_m: f64,
    depth_m: f64,
    material: MaterialId,
) -> Result<Mesh, TargetError> {
    const RINGS: u32 = 4;
    // 24 segments: a dish on the body axis keeps a 2-, 3- or 4-fold symmetry.
    const SEGMENTS: u32 = 24;
    let mut vertices = vec![Vector3::zeros()];
    for i in 1..=RINGS {
        let r = radius_m * f64::from(i) / f64::from(RINGS);
        let x = depth_m * (r / radius_m).powi(2);
        for k in 0..SEGMENTS {
            let phi = 2.0 * PI * f64::from(k) / f64::from(SEGMENTS);
            vertices.push(Vector3::new(x, r * phi.cos(), r * phi.sin()));
        }
    }
    let at = |ring: u32, k: u32| 1 + (ring - 1) * SEGMENTS + k % SEGMENTS;
    let mut triangles = Vec::new();
    for k in 0..SEGMENTS {
        triangles.push([0, at(1, k), at(1, k + 1)]);
    }
    for i in 1..RINGS {
        for k in 0..SEGMENTS {
            triangles.push([at(i, k), at(i + 1, k), at(i + 1, k + 1)]);
            triangles.push([at(i, k), at(i + 1, k + 1), at(i, k + 1)]);
        }
    }
    let materials = vec![material; triangles.len()];
    Mesh::new(vertices, triangles, materials)?.transformed(&x_to(axis), &vertex)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn x_to_maps_x_onto_every_direction() {
        for d in [Vector3::x(), -Vector3::x(), Vector3::y(), radial(2.0)] {
            assert!((x_to(&d) * Vector3::x() - d).norm() < 1e-12);
        }
    }

    #[test]
    fn a_dish_faces_its_axis_and_has_its_rim() {
        let axis = Vector3::z();
        let m = dish(Vector3::new(1.0, 0.0, 0.0), &axis, 0.5, 0.1, ALUMINIUM).expect("dish");
        let far = m
            .vertices()
            .iter()
            .map(|v| (v - Vector3::new(1.0, 0.0, 0.0)).norm())
            .fold(0.0, f64::max);
        assert!((far - (0.25f64 + 0.01).sqrt()).abs() < 1e-9);
        // Seen from +z the dish is hit (on its inner surface).
        let hit = m.cast_ray(&Vector3::new(1.0, 0.0, 5.0), &-Vector3::z(), 10.0);
        assert!(hit.is_some());
    }

    #[test]
    fn a_cone_along_y_spans_its_length() {
        let m = frustum(
            Vector3::zeros(),
            &Vector3::y(),
            2.0,
            [0.5, 0.0],
            8,
            0.0,
            STRUCTURE,
        )
        .expect("cone");
        let ys: Vec<f64> = m.vertices().iter().map(|v| v.y).collect();
        let max = ys.iter().copied().fold(f64::MIN, f64::max);
        let min = ys.iter().copied().fold(f64::MAX, f64::min);
        assert!((max - 2.0).abs() < 1e-12 && min.abs() < 1e-12);
    }
}
