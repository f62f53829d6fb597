//! A deterministic, simulator-free spacecraft-like fixture for tests and
//! benchmarks: a hexagonal-prism bus with a solar panel and an instrument
//! box, sampled on planes, and the partial frames a lidar would see of it
//! (back-face culling + a z-buffer + a 2 cm voxel filter), static or
//! motion-blurred.

use crate::ct_ndt::interpolate;
use nalgebra::Vector3;
use spacepose_geometry::{Point, Pose};
use std::collections::HashMap;

/// A planar parallelogram `origin + a·s + b·t`, `s, t ∈ [0, 1]`, with its
/// outward unit normal.
#[derive(Debug, Clone, Copy)]
struct Face {
    origin: Vector3<f64>,
    a: Vector3<f64>,
    b: Vector3<f64>,
    normal: Vector3<f64>,
    double_sided: bool,
}

impl Face {
    fn new(origin: Vector3<f64>, a: Vector3<f64>, b: Vector3<f64>, outward: Vector3<f64>) -> Self {
        let n = a.cross(&b).normalize();
        let normal = if n.dot(&outward) >= 0.0 { n } else { -n };
        Self {
            origin,
            a,
            b,
            normal,
            double_sided: false,
        }
    }

    fn sheet(origin: Vector3<f64>, a: Vector3<f64>, b: Vector3<f64>) -> Self {
        Self {
            double_sided: true,
            ..Self::new(origin, a, b, a.cross(&b))
        }
    }
}

/// A model point with the outward normal of its face.
#[derive(Debug, Clone, Copy)]
pub struct SurfacePoint {
    /// Position (target body frame, m).
    pub position: Vector3<f64>,
    /// Outward unit normal (target body frame).
    pub normal: Vector3<f64>,
    /// True for a zero-thickness sheet seen from both sides.
    pub double_sided: bool,
}

/// The spacecraft-like target: sampled surface points with normals.
#[derive(Debug, Clone)]
pub struct SyntheticTarget {
    /// Surface samples (target body frame).
    pub surface: Vec<SurfacePoint>,
}

/// The six faces of an axis-aligned box, optionally without its -z face.
fn box_faces(centre: Vector3<f64>, size: Vector3<f64>, with_bottom: bool) -> Vec<Face> {
    let h = size * 0.5;
    let (ex, ey, ez) = (
        Vector3::x() * size.x,
        Vector3::y() * size.y,
        Vector3::z() * size.z,
    );
    let c = |sx: f64, sy: f64, sz: f64| centre + Vector3::new(sx * h.x, sy * h.y, sz * h.z);
    let mut faces = vec![
        Face::new(c(1.0, -1.0, -1.0), ey, ez, Vector3::x()),
        Face::new(c(-1.0, -1.0, -1.0), ey, ez, -Vector3::x()),
        Face::new(c(-1.0, 1.0, -1.0), ex, ez, Vector3::y()),
        Face::new(c(-1.0, -1.0, -1.0), ex, ez, -Vector3::y()),
        Face::new(c(-1.0, -1.0, 1.0), ex, ey, Vector3::z()),
    ];
    if with_bottom {
        faces.push(Face::new(c(-1.0, -1.0, -1.0), ex, ey, -Vector3::z()));
    }
    faces
}

/// Hexagonal prism of circumradius `r` and height `height` along z, centred
/// at the origin: six side rectangles and two caps made of three rhombi.
fn hex_prism_faces(r: f64, height: f64) -> Vec<Face> {
    let v = |k: usize| {
        let a = std::f64::consts::FRAC_PI_3 * k as f64;
        Vector3::new(r * a.cos(), r * a.sin(), 0.0)
    };
    let (bottom, up) = (Vector3::new(0.0, 0.0, -height / 2.0), Vector3::z() * height);
    let mut faces = Vec::new();
    for k in 0..6 {
        let (p, q) = (v(k), v(k + 1));
        faces.push(Face::new(bottom + p, q - p, up, (p + q) * 0.5));
    }
    for cap_z in [-height / 2.0, height / 2.0] {
        let o = Vector3::new(0.0, 0.0, cap_z);
        for k in [0, 2, 4] {
            faces.push(Face::new(o, v(k), v(k + 2), Vector3::z() * cap_z));
        }
    }
    faces
}

impl SyntheticTarget {
    /// The default target sampled every `spacing_m` (about 1 cm gives some
    /// 100k points): a 1.4 m tall hexagonal bus of radius 0.6 m, a
    /// 2 m × 0.7 m solar-panel sheet on its +x side, and a 0.3 × 0.3 × 0.4 m box on
    /// its top, off-centre so that the shape has no symmetry.
    pub fn spacecraft(spacing_m: f64) -> Self {
        let mut faces = hex_prism_faces(0.6, 1.4);
        // The panel is a zero-thickness sheet: a 3 cm thick plate would sit
        // inside single NDT cells, whose means fall in its mid-plane.
        faces.push(Face::sheet(
            Vector3::new(0.8, -0.35, 0.2),
            Vector3::x() * 2.0,
            Vector3::y() * 0.7,
        ));
        faces.extend(box_faces(
            Vector3::new(0.1, -0.15, 0.9),
            Vector3::new(0.3, 0.3, 0.4),
            false,
        ));
        let mut surface = Vec::new();
        let mut state = 0x5eed_u64;
        for f in &faces {
            let na = (f.a.norm() / spacing_m).ceil().max(1.0) as usize;
            let nb = (f.b.norm() / spacing_m).ceil().max(1.0) as usize;
            for i in 0..na {
                for j in 0..nb {
                    // Jittered grid: one uniform sample per grid cell, so the
                    // model and the voxel-filtered frames never share a lattice
                    // (a regular lattice biases point-to-point ICP by aliasing).
                    let s = (i as f64 + jitter(&mut state)) / na as f64;
                    let t = (j as f64 + jitter(&mut state)) / nb as f64;
                    surface.push(SurfacePoint {
                        position: f.origin + f.a * s + f.b * t,
                        normal: f.normal,
                        double_sided: f.double_sided,
                    });
                }
            }
        }
        Self { surface }
    }

    /// The model cloud (positions only, target body frame).
    pub fn model(&self) -> Vec<Vector3<f64>> {
        self.surface.iter().map(|s| s.position).collect()
    }

    /// The surface points visible from the sensor (sensor frame) when the
    /// target is at `t_sensor_target`: faces turned towards the sensor,
    /// then a z-buffer over bins of `bin_rad` in both angles keeping the
    /// points within 2 cm of each bin's nearest depth.
    pub fn visible(&self, t_sensor_target: &Pose, bin_rad: f64) -> Vec<Vector3<f64>> {
        let facing: Vec<Vector3<f64>> = self
            .surface
            .iter()
            .filter_map(|s| {
                let p = t_sensor_target.transform(&s.position);
                let n = t_sensor_target.rotation * s.normal;
                ((n.dot(&p) < 0.0 || s.double_sided) && p.z > 0.0).then_some(p)
            })
            .collect();
        let bin = |p: &Vector3<f64>| {
            (
                (p.x / p.z / bin_rad).floor() as i64,
                (p.y / p.z / bin_rad).floor() as i64,
            )
        };
        let mut nearest: HashMap<(i64, i64), f64> = HashMap::new();
        for p in &facing {
            let d = nearest.entry(bin(p)).or_insert(f64::INFINITY);
            *d = d.min(p.norm());
        }
        facing
            .into_iter()
            .filter(|p| p.norm() <= nearest[&bin(p)] + 0.02)
            .collect()
    }

    /// A static frame: the visible points at `t_sensor_target`, voxel
    /// filtered at `voxel_m` (sensor frame, all timestamps 0).
    pub fn frame(&self, t_sensor_target: &Pose, voxel_m: f64) -> Vec<Point> {
        voxel_filter(&self.visible(t_sensor_target, 0.0015), voxel_m)
            .iter()
            .map(|p| Point::from_vector(p, 1.0, 0.0))
            .collect()
    }

    /// A motion-blurred frame, scanned left to right between `t_start_s`
    /// and `t_end_s` while the pose `t_target_sensor` moves from `start` to
    /// `end` (seed 000 Eq. 13 interpolation). Visibility and the voxel
    /// filter are evaluated at the middle pose; each voxel centroid then
    /// gets the timestamp of its azimuth within the sweep and is placed
    /// where the sensor sees it at that time, `z = T(u)⁻¹ m`.
    pub fn blurred_frame(
        &self,
        start: &Pose,
        end: &Pose,
        t_start_s: f64,
        t_end_s: f64,
        voxel_m: f64,
    ) -> Vec<Point> {
        let mid = interpolate(start, end, 0.5);
        let t_sensor_target = mid.inverse();
        let centroids = voxel_filter(&self.visible(&t_sensor_target, 0.0015), voxel_m);
        let azimuth = |p: &Vector3<f64>| p.x.atan2(p.z);
        let (lo, hi) = centroids
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                (l.min(azimuth(p)), h.max(azimuth(p)))
            });
        let span = (hi - lo).max(1e-12);
        centroids
            .iter()
            .map(|c| {
                let u = (azimuth(c) - lo) / span;
                let m = mid.transform(c);
                let z = interpolate(start, end, u).inverse().transform(&m);
                Point::from_vector(&z, 1.0, t_start_s + u * (t_end_s - t_start_s))
            })
            .collect()
    }
}

/// A deterministic uniform number in `[0, 1)` (SplitMix64), so the
/// fixture needs no RNG dependency and is identical on every machine.
fn jitter(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// Mean of the points falling in each cubic voxel of edge `voxel_m`, in
/// first-seen order (deterministic).
pub fn voxel_filter(points: &[Vector3<f64>], voxel_m: f64) -> Vec<Vector3<f64>> {
    let mut index: HashMap<[i64; 3], usize> = HashMap::new();
    let mut sums: Vec<(Vector3<f64>, usize)> = Vec::new();
    for p in points {
        let key = [
            (p.x / voxel_m).floor() as i64,
            (p.y / voxel_m).floor() as i64,
            (p.z / voxel_m).floor() as i64,
        ];
        let slot = *index.entry(key).or_insert_with(|| {
            sums.push((Vector3::zeros(), 0));
            sums.len() - 1
        });
        sums[slot].0 += p;
        sums[slot].1 += 1;
    }
    sums.into_iter().map(|(s, n)| s / n as f64).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use spacepose_geometry::so3;

    #[test]
    fn model_and_frame_have_realistic_sizes() {
        let target = SyntheticTarget::spacecraft(0.01);
        let n = target.surface.len();
        assert!((60_000..200_000).contains(&n), "{n} model points");
        let t_sensor_target = Pose::new(
            so3::exp(&Vector3::new(0.3, -0.5, 0.2)),
            Vector3::new(0.1, -0.2, 6.0),
        );
        let frame = target.frame(&t_sensor_target, 0.02);
        assert!(
            (3_000..30_000).contains(&frame.len()),
            "{} frame points",
            frame.len()
        );
        // Every frame point lies on the model surface (within the voxel size).
        let t_target_sensor = t_sensor_target.inverse();
        let model = target.model();
        for p in frame.iter().step_by(97) {
            let m = t_target_sensor.transform(&p.position());
            let d = model
                .iter()
                .map(|q| (q - m).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(d < 0.02, "{d}");
        }
    }
}
