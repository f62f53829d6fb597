//! Ray casting and point-to-surface distance on a [`Mesh`]: the bounding-sphere rejection,
//! the `f32` BVH query and the exact `f64` refinement described in the parent module.

use nalgebra::Vector3;
use parry3d::query::{PointQuery, Ray};
use parry3d::shape::CompositeShapeRef;

use super::{Mesh, RayHit, to_f32};

impl Mesh {
    /// First intersection of the ray `origin + t * dir_unit`, `0 <= t <= max_range`, with the
    /// mesh (both sides of every triangle are hit). `dir_unit` is normalised here in case it
    /// is not exactly unit; the distance is along the unit direction. Returns `None` on a
    /// miss and for a non-finite origin, a zero or non-finite direction, or `max_range <= 0`.
    ///
    /// A ray that starts on the surface (e.g. a reflected ray) may hit its own face at a
    /// distance ≈ 0: move its origin off the surface first (about 1e-4 of the mesh size
    /// along the returned normal is plenty for the `f32` BVH).
    #[inline]
    pub fn cast_ray(
        &self,
        origin: &Vector3<f64>,
        dir_unit: &Vector3<f64>,
        max_range: f64,
    ) -> Option<RayHit> {
        let norm = dir_unit.norm();
        if !(norm > 0.0 && norm.is_finite() && max_range > 0.0) {
            return None;
        }
        if !(origin.x.is_finite() && origin.y.is_finite() && origin.z.is_finite()) {
            return None;
        }
        let dir = dir_unit / norm;
        let (t_enter, t_exit) = self.sphere_interval(origin, &dir)?;
        if t_enter > max_range {
            return None;
        }
        // Start a little before the sphere entry so f32 coordinates stay small.
        let margin = 1e-4 * self.sphere_radius + 1e-6;
        let t_start = (t_enter - margin).max(0.0);
        let t_end = t_exit.min(max_range);
        let ray = Ray::new(to_f32(&(origin + dir * t_start)), to_f32(&dir));
        let max_toi = ((t_end - t_start) * (1.0 + 1e-5) + 1e-5) as f32;
        let (face, toi) = CompositeShapeRef(&self.bvh).cast_local_ray(&ray, max_toi, false)?;
        self.refine_hit(origin, &dir, face, t_start + f64::from(toi), max_range)
    }

    /// Parameter interval `[t_enter, t_exit]` (t_enter clamped at 0) where the ray is inside
    /// the (slightly inflated) bounding sphere; `None` if it never is.
    #[inline]
    fn sphere_interval(&self, origin: &Vector3<f64>, dir: &Vector3<f64>) -> Option<(f64, f64)> {
        let r = self.sphere_radius * (1.0 + 1e-6) + 1e-6;
        let oc = origin - self.sphere_center;
        let b = oc.dot(dir);
        let c = oc.norm_squared() - r * r;
        if c > 0.0 && b > 0.0 {
            return None; // outside and moving away
        }
        let disc = b * b - c;
        if disc < 0.0 {
            return None;
        }
        let sq = disc.sqrt();
        Some(((-b - sq).max(0.0), -b + sq))
    }

    /// Exact `f64` distance and normal on the plane of the triangle found in `f32`.
    #[inline]
    fn refine_hit(
        &self,
        origin: &Vector3<f64>,
        dir: &Vector3<f64>,
        face: u32,
        toi_f32: f64,
        max_range: f64,
    ) -> Option<RayHit> {
        let i = face as usize;
        let n = self.face_normals[i];
        let denom = n.dot(dir);
        let a = self.vertices[self.triangles[i][0] as usize];
        let t = if denom.abs() > 1e-9 {
            n.dot(&(a - origin)) / denom
        } else {
            toi_f32
        };
        let distance = t.max(0.0);
        if distance > max_range {
            return None;
        }
        let normal = if denom > 0.0 { -n } else { n };
        Some(RayHit {
            distance,
            normal,
            face,
            material: self.face_materials[i],
        })
    }

    /// Distance (m) from `point` to the nearest point of the mesh surface (`f32` precision,
    /// i.e. about 1e-7 of the mesh size).
    pub fn distance_to_surface(&self, point: &Vector3<f64>) -> f64 {
        let p = to_f32(point);
        let proj = self.bvh.project_local_point(p, false);
        let q = Vector3::new(
            f64::from(proj.point.x),
            f64::from(proj.point.y),
            f64::from(proj.point.z),
        );
        (point - q).norm()
    }
}
