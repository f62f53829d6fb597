//! Primitive solids beyond the cuboid: right prisms over a regular polygon (hexagonal bodies,
//! cylinders approximated by many-sided prisms).

use nalgebra::Vector3;

use crate::error::TargetError;
use crate::material::MaterialId;
use crate::mesh::{Mesh, orient_outward};

/// Right prism along the x axis over a regular `sides`-gon of circumradius `radius_m`,
/// spanning `x_min_m..x_max_m`, polygon vertices at angles `phase_rad + 2πk/sides` about
/// x measured from +y toward +z (vertex `k` at `(y, z) = r (cos φ_k, sin φ_k)`).
///
/// Each end cap is a fan around its centre, so the triangulation has the polygon's rotational
/// symmetry. Side faces get `side_material`, the two caps `cap_material`.
pub(crate) fn regular_prism_x(
    sides: u32,
    radius_m: f64,
    x_min_m: f64,
    x_max_m: f64,
    phase_rad: f64,
    side_material: MaterialId,
    cap_material: MaterialId,
) -> Result<Mesh, TargetError> {
    frustum_x(
        sides,
        [radius_m, radius_m],
        [x_min_m, x_max_m],
        phase_rad,
        side_material,
        cap_material,
    )
}

/// A frustum along x over regular `sides`-gons: circumradius `radii_m[0]`
/// at `x_m[0]` and `radii_m[1]` at `x_m[1]` (a zero radius makes a cone;
/// its cap's triangles have no area and are harmless). Vertex conventions
/// and materials as [`regular_prism_x`].
pub(crate) fn frustum_x(
    sides: u32,
    radii_m: [f64; 2],
    x_m: [f64; 2],
    phase_rad: f64,
    side_material: MaterialId,
    cap_material: MaterialId,
) -> Result<Mesh, TargetError> {
    if sides < 3 {
        return Err(TargetError::InvalidMesh(format!(
            "a prism needs at least 3 sides, got {sides}"
        )));
    }
    let ring = |x: f64, r: f64| {
        (0..sides).map(move |k| {
            let phi = phase_rad + std::f64::consts::TAU * f64::from(k) / f64::from(sides);
            Vector3::new(x, r * phi.cos(), r * phi.sin())
        })
    };
    // Vertices: ring at x_m[0] (0..n), ring at x_m[1] (n..2n), cap centres 2n and 2n + 1.
    let n = sides;
    let mut vertices: Vec<Vector3<f64>> = ring(x_m[0], radii_m[0])
        .chain(ring(x_m[1], radii_m[1]))
        .collect();
    vertices.push(Vector3::new(x_m[0], 0.0, 0.0));
    vertices.push(Vector3::new(x_m[1], 0.0, 0.0));
    let mut triangles = Vec::with_capacity(4 * n as usize);
    let mut materials = Vec::with_capacity(4 * n as usize);
    for k in 0..n {
        let k1 = (k + 1) % n;
        triangles.push([k, k1, n + k1]);
        triangles.push([k, n + k1, n + k]);
        materials.extend([side_material, side_material]);
    }
    for k in 0..n {
        let k1 = (k + 1) % n;
        triangles.push([2 * n, k, k1]);
        triangles.push([2 * n + 1, n + k, n + k1]);
        materials.extend([cap_material, cap_material]);
    }
    let interior = Vector3::new(0.5 * (x_m[0] + x_m[1]), 0.0, 0.0);
    let triangles = orient_outward(&vertices, triangles, &interior);
    Mesh::new(vertices, triangles, materials)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hexagonal_prism_area_and_hits() {
        let r = 0.9;
        let m = regular_prism_x(6, r, -1.0, 1.0, 0.0, 1, 2).expect("prism");
        assert_eq!(m.triangle_count(), 24);
        let cap = 1.5 * 3f64.sqrt() * r * r;
        let area = 6.0 * r * 2.0 + 2.0 * cap;
        assert!((m.surface_area() - area).abs() < 1e-12);
        // From +x: the cap at x = 1 (material 2).
        let hit = m
            .cast_ray(&Vector3::new(5.0, 0.1, 0.2), &-Vector3::x(), 10.0)
            .expect("hit");
        assert!((hit.distance - 4.0).abs() < 1e-12);
        assert_eq!(hit.material, 2);
        // From -z: a side face, at the apothem r cos 30°; material 1.
        let hit = m
            .cast_ray(&Vector3::new(0.3, 0.0, -5.0), &Vector3::z(), 10.0)
            .expect("hit");
        let apothem = r * (30f64.to_radians()).cos();
        assert!((hit.distance - (5.0 - apothem)).abs() < 1e-12);
        assert_eq!(hit.material, 1);
        assert!(regular_prism_x(2, r, -1.0, 1.0, 0.0, 1, 2).is_err());
    }
}
