//! Area-uniform, evenly spread surface sampling (model clouds for NDT / ICP).
//!
//! Each triangle is laid in its own 2D frame (x along its longest edge, y toward the opposite
//! vertex) and covered by a square grid of pitch `spacing`, shifted by a random offset; one
//! point is drawn uniformly in every grid cell and kept if it falls inside the triangle.
//! Every surface point therefore has the same probability density `1 / spacing²`: the
//! expected count is exactly `area / spacing²` and the points are spread like a jittered grid
//! (no clumps and holes as with i.i.d. draws), which suits NDT cells. The generator is
//! `ChaCha8Rng::seed_from_u64(seed)`, so the cloud is reproducible on every platform.

use nalgebra::Vector3;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::error::TargetError;
use crate::mesh::Mesh;

/// Largest number of grid cells (≈ candidate points) one call may visit.
pub const MAX_SAMPLES: f64 = 5e7;

/// Samples the surface of `mesh` with about `area / spacing_m²` points (see module docs).
///
/// Errors if `spacing_m` is not finite and > 0, or if the grid would exceed
/// [`MAX_SAMPLES`] cells.
pub fn sample_mesh_surface(
    mesh: &Mesh,
    spacing_m: f64,
    seed: u64,
) -> Result<Vec<Vector3<f64>>, TargetError> {
    let err = |message: String| TargetError::InvalidSpacing { spacing_m, message };
    if !(spacing_m.is_finite() && spacing_m > 0.0) {
        return Err(err("must be finite and > 0".to_owned()));
    }
    let frames: Vec<TriangleFrame> = mesh
        .triangles()
        .iter()
        .zip(mesh.face_areas())
        .filter(|&(_, &area)| area > 0.0)
        .map(|(t, _)| TriangleFrame::new(t.map(|k| mesh.vertices()[k as usize])))
        .collect();
    let cells: f64 = frames
        .iter()
        .map(|f| (f.base / spacing_m + 1.0).ceil() * (f.height / spacing_m + 1.0).ceil())
        .sum();
    if cells > MAX_SAMPLES {
        return Err(err(format!(
            "{cells:.3e} grid cells exceed the limit {MAX_SAMPLES:.0e}"
        )));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let expected = mesh.surface_area() / (spacing_m * spacing_m);
    let mut points = Vec::with_capacity((expected * 1.05) as usize + 16);
    for f in &frames {
        f.sample(spacing_m, &mut rng, &mut points);
    }
    Ok(points)
}

/// A triangle in its 2D frame: vertices (0, 0), (base, 0), (apex_x, height).
struct TriangleFrame {
    origin: Vector3<f64>,
    u: Vector3<f64>,
    v: Vector3<f64>,
    base: f64,
    apex_x: f64,
    height: f64,
}

impl TriangleFrame {
    /// Frame with x along the longest edge, so that `0 <= apex_x <= base`.
    fn new(p: [Vector3<f64>; 3]) -> TriangleFrame {
        let edges = [(0, 1, 2), (1, 2, 0), (2, 0, 1)];
        let (i, j, k) = edges
            .into_iter()
            .max_by(|a, b| {
                (p[a.1] - p[a.0])
                    .norm()
                    .total_cmp(&(p[b.1] - p[b.0]).norm())
            })
            .unwrap_or((0, 1, 2));
        let e = p[j] - p[i];
        let base = e.norm();
        let u = e / base;
        let w = p[k] - p[i];
        let apex_x = w.dot(&u);
        let perp = w - u * apex_x;
        let height = perp.norm();
        TriangleFrame {
            origin: p[i],
            u,
            v: perp / height,
            base,
            apex_x,
            height,
        }
    }

    fn contains(&self, x: f64, y: f64) -> bool {
        if !(0.0..=self.height).contains(&y) {
            return false;
        }
        let s = y / self.height;
        x >= self.apex_x * s && x <= self.base + (self.apex_x - self.base) * s
    }

    /// One uniform point per cell of a randomly shifted grid of pitch `spacing`.
    fn sample(&self, spacing: f64, rng: &mut ChaCha8Rng, out: &mut Vec<Vector3<f64>>) {
        let x0 = -rng.random_range(0.0..spacing);
        let y0 = -rng.random_range(0.0..spacing);
        let nx = ((self.base - x0) / spacing).ceil() as u64;
        let ny = ((self.height - y0) / spacing).ceil() as u64;
        for iy in 0..ny {
            for ix in 0..nx {
                let x = x0 + (ix as f64 + rng.random_range(0.0..1.0)) * spacing;
                let y = y0 + (iy as f64 + rng.random_range(0.0..1.0)) * spacing;
                if self.contains(x, y) {
                    out.push(self.origin + self.u * x + self.v * y);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    fn slab() -> Mesh {
        Mesh::cuboid(
            Vector3::new(0.3, -0.2, 0.1),
            Vector3::new(1.0, 0.5, 0.05),
            Rotation3::from_euler_angles(0.2, 0.4, -0.3),
            0,
        )
    }

    #[test]
    fn count_is_area_over_spacing_squared_and_points_lie_on_surface() {
        let mesh = slab();
        let spacing = 0.02;
        let pts = sample_mesh_surface(&mesh, spacing, 3).expect("sample");
        let expected = mesh.surface_area() / (spacing * spacing);
        let rel = (pts.len() as f64 - expected).abs() / expected;
        assert!(rel < 0.02, "{} points for {expected}", pts.len());
        assert!(pts.iter().all(|p| mesh.distance_to_surface(p) < 1e-5));
    }

    #[test]
    fn density_is_uniform_across_faces() {
        // Big face (2 m x 1 m, two triangles of different shapes) vs its share of the cloud.
        let mesh = slab();
        let pts = sample_mesh_surface(&mesh, 0.01, 9).expect("sample");
        let n_big = mesh.face_normals()[..]
            .iter()
            .zip(mesh.face_areas())
            .filter(|&(_, &a)| (a - 1.0).abs() < 1e-9)
            .count();
        assert_eq!(n_big, 4, "the two 2 m x 1 m faces are 4 triangles of 1 m²");
        let rot = Rotation3::from_euler_angles(0.2, 0.4, -0.3);
        let c = Vector3::new(0.3, -0.2, 0.1);
        let on_top = pts
            .iter()
            .filter(|p| (rot.inverse() * (*p - c)).z > 0.05 - 1e-9)
            .count() as f64;
        let share = 2.0 / mesh.surface_area();
        let got = on_top / pts.len() as f64;
        assert!((got - share).abs() < 0.01, "{got} vs {share}");
    }

    #[test]
    fn deterministic_per_seed() {
        let mesh = slab();
        let a = sample_mesh_surface(&mesh, 0.05, 1).expect("a");
        let b = sample_mesh_surface(&mesh, 0.05, 1).expect("b");
        let c = sample_mesh_surface(&mesh, 0.05, 2).expect("c");
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn rejects_bad_spacing() {
        let mesh = slab();
        assert!(sample_mesh_surface(&mesh, 0.0, 1).is_err());
        assert!(sample_mesh_surface(&mesh, -1.0, 1).is_err());
        assert!(sample_mesh_surface(&mesh, f64::INFINITY, 1).is_err());
        assert!(sample_mesh_surface(&mesh, 1e-6, 1).is_err());
    }
}
