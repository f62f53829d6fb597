//! The model's depth image at a predicted pose: for each direction from the
//! sensor, the range of the nearest model surface (a z-buffer of the model
//! cloud). [`crate::visibility`] asks it whether a point lies behind every
//! surface the model can show near the point's ray, within a disc that
//! covers the pose's uncertainty at the point's own depth.
//!
//! Directions are pixels of the plane tangent to the line of sight to the
//! target's origin (`u = x·e₁ / x·l`, `v = x·e₂ / x·l`), so any sensor
//! geometry works. The pixel is twice the model cloud's spacing seen from
//! the nearest point of the target's bounding sphere, so that every pixel
//! the model covers holds at least one model point: an empty pixel inside
//! the silhouette would read as "no surface" and keep the points behind it.
//!
//! The neighbourhood is a disc, sized per point: a surface that could,
//! displaced by the margin, lie on the point's ray at or beyond the point's
//! range less the tolerance is at least `|x| − tolerance − margin` away, so
//! it lies within `margin / (|x| − tolerance − margin)` of the ray (times the
//! tangent plane's stretch off-axis). The first version widened the whole
//! image by a square maximum filter whose half-width was the margin seen
//! from the bounding sphere's nearest point, rounded up to whole pixels:
//! on development design `zoo:1001` (scenario seed 2023, frame 50) that
//! neighbourhood reached about 0.65 m at the face where reflection ghosts
//! lay 0.44 m behind, and the gate dropped about a quarter of them, where a
//! disc of the 0.3 m margin drops over 90 % (docs/design/visibility-gate.md).

use nalgebra::Vector3;
use spacepose_geometry::Pose;

/// Largest image side (pixels): beyond it the pixel grows instead.
const MAX_SIDE: usize = 512;

/// A depth image of a model cloud.
#[derive(Debug, Clone)]
pub struct DepthImage {
    /// Unit line of sight to the target's origin (sensor frame).
    l: Vector3<f64>,
    e1: Vector3<f64>,
    e2: Vector3<f64>,
    /// Pixel size in tangent-plane units (≈ rad).
    pixel: f64,
    /// Tangent-plane coordinate of the first pixel's edge, both axes.
    origin: f64,
    side: usize,
    /// Per pixel, the range of the nearest model point projected into it
    /// (m); +∞ where none is.
    near: Vec<f32>,
}

impl DepthImage {
    /// The image of `model_target` (body frame, sampled every `spacing_m`,
    /// inside a sphere of `radius_m` about the origin) seen at
    /// `t_sensor_target`. `None` when the sensor is inside the bounding
    /// sphere (no tangent plane holds the target).
    pub fn render(
        model_target: &[Vector3<f64>],
        spacing_m: f64,
        radius_m: f64,
        t_sensor_target: &Pose,
    ) -> Option<Self> {
        let centre = t_sensor_target.translation;
        let range = centre.norm();
        let nearest = range - radius_m;
        if !(nearest > spacing_m && range.is_finite()) {
            return None;
        }
        let l = centre / range;
        let helper = if l.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let e1 = l.cross(&helper).normalize();
        let e2 = l.cross(&e1);
        // The half-angle of the bounding sphere, in tangent-plane units.
        let half = radius_m / (range * range - radius_m * radius_m).max(0.0).sqrt();
        let mut pixel = 2.0 * spacing_m / nearest;
        let mut side = (2.0 * half / pixel).ceil() as usize + 2;
        if side > MAX_SIDE {
            pixel *= side as f64 / MAX_SIDE as f64;
            side = MAX_SIDE;
        }
        let mut image = DepthImage {
            l,
            e1,
            e2,
            pixel,
            origin: -(side as f64) * pixel / 2.0,
            side,
            near: vec![f32::INFINITY; side * side],
        };
        for m in model_target {
            let x = t_sensor_target.transform(m);
            if let Some((u, v)) = image.plane_of(&x)
                && let Some(i) = image.index(u.floor(), v.floor())
            {
                image.near[i] = image.near[i].min(x.norm() as f32);
            }
        }
        Some(image)
    }

    /// Whether `x` (sensor frame) can be a return of a model surface
    /// displaced by up to `margin_m`: some pixel of the point's disc holds a
    /// surface at most `tolerance_m` in front of it, or no pixel of the disc
    /// holds a surface (beside the target), or the point is outside the
    /// image.
    pub fn may_be_surface(&self, x: &Vector3<f64>, margin_m: f64, tolerance_m: f64) -> bool {
        let Some((u, v)) = self.plane_of(x) else {
            return true;
        };
        let range = x.norm();
        let reach = margin_m / (range - tolerance_m - margin_m).max(margin_m.max(1e-3));
        // The tangent plane stretches a lateral displacement off the axis.
        let (tu, tv) = (u * self.pixel + self.origin, v * self.pixel + self.origin);
        let stretch = (1.0 + tu * tu + tv * tv).sqrt() * (1.0 + tu.abs().max(tv.abs()));
        // A model point may lie anywhere in its pixel: half a diagonal more.
        let r = reach * stretch / self.pixel + std::f64::consts::FRAC_1_SQRT_2;
        let limit = range as f32 - tolerance_m as f32;
        let mut any_surface = false;
        let (lo_u, hi_u) = ((u - r).floor().max(0.0), (u + r).floor());
        let (lo_v, hi_v) = ((v - r).floor().max(0.0), (v + r).floor());
        let mut pv = lo_v;
        while pv <= hi_v {
            let mut pu = lo_u;
            while pu <= hi_u {
                let (du, dv) = (pu + 0.5 - u, pv + 0.5 - v);
                if du * du + dv * dv <= r * r
                    && let Some(i) = self.index(pu, pv)
                {
                    let near = self.near[i];
                    if near.is_finite() {
                        if near >= limit {
                            return true;
                        }
                        any_surface = true;
                    }
                }
                pu += 1.0;
            }
            pv += 1.0;
        }
        !any_surface
    }

    /// A sensor-frame position's continuous pixel coordinates, `None`
    /// behind the sensor's plane through the origin or outside the image.
    fn plane_of(&self, x: &Vector3<f64>) -> Option<(f64, f64)> {
        let d = x.dot(&self.l);
        if d <= 0.0 {
            return None;
        }
        let u = (x.dot(&self.e1) / d - self.origin) / self.pixel;
        let v = (x.dot(&self.e2) / d - self.origin) / self.pixel;
        let side = self.side as f64;
        (u >= 0.0 && v >= 0.0 && u < side && v < side).then_some((u, v))
    }

    /// The index of whole pixel coordinates, `None` outside the image.
    fn index(&self, u: f64, v: f64) -> Option<usize> {
        let side = self.side as f64;
        (u >= 0.0 && v >= 0.0 && u < side && v < side).then(|| v as usize * self.side + u as usize)
    }

    /// Image side (pixels).
    #[cfg(test)]
    pub fn side(&self) -> usize {
        self.side
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    /// The faces z = ±0.5 of a unit square plate pair, sampled every 2 cm.
    fn two_plates() -> Vec<Vector3<f64>> {
        let mut pts = Vec::new();
        for i in 0..=50 {
            for j in 0..=50 {
                let (x, y) = (i as f64 * 0.02 - 0.5, j as f64 * 0.02 - 0.5);
                pts.push(Vector3::new(x, y, -0.5));
                pts.push(Vector3::new(x, y, 0.5));
            }
        }
        pts
    }

    fn at(z: f64) -> Pose {
        Pose::new(Rotation3::identity(), Vector3::new(0.0, 0.0, z))
    }

    #[test]
    fn a_point_behind_the_near_plate_is_no_surface_and_one_beside_it_is() {
        let img = DepthImage::render(&two_plates(), 0.02, 0.75, &at(10.0)).unwrap();
        // On the near plate (9.5 m) and just behind it: a surface return.
        assert!(img.may_be_surface(&Vector3::new(0.0, 0.0, 9.5), 0.05, 0.15));
        assert!(img.may_be_surface(&Vector3::new(0.0, 0.0, 9.6), 0.05, 0.15));
        // The far plate (10.5 m) is hidden behind the near one: no return
        // comes from it, nor from between the plates.
        assert!(!img.may_be_surface(&Vector3::new(0.0, 0.0, 10.5), 0.05, 0.15));
        assert!(!img.may_be_surface(&Vector3::new(0.0, 0.0, 10.0), 0.05, 0.15));
        // Beside the target anything goes.
        assert!(img.may_be_surface(&Vector3::new(2.0, 0.0, 10.0), 0.05, 0.15));
        assert!(img.side() > 10 && img.side() < MAX_SIDE);
    }

    #[test]
    fn the_disc_covers_the_margin_at_the_points_depth_and_no_more() {
        // A small near plate (0.5 m square at 9.5 m) before a large far one
        // (1 m square at 10.5 m), which shows around it. A point 0.3 m
        // behind the near plate, 0.1 m inside its edge: with a 0.05 m
        // margin the disc holds only the near plate, so the point is no
        // surface return; with 0.3 m the disc reaches past the edge to the
        // far plate, which, displaced, could be on the point's ray.
        let mut pts = Vec::new();
        for i in 0..=50 {
            for j in 0..=50 {
                let (x, y) = (i as f64 * 0.02 - 0.5, j as f64 * 0.02 - 0.5);
                pts.push(Vector3::new(x, y, 0.5));
                if x.abs() <= 0.25 && y.abs() <= 0.25 {
                    pts.push(Vector3::new(x, y, -0.5));
                }
            }
        }
        let img = DepthImage::render(&pts, 0.02, 0.75, &at(10.0)).unwrap();
        let x = Vector3::new(0.15 * 9.8 / 9.5, 0.0, 9.8);
        assert!(!img.may_be_surface(&x, 0.05, 0.15));
        assert!(img.may_be_surface(&x, 0.3, 0.15));
    }

    #[test]
    fn inside_the_bounding_sphere_there_is_no_image() {
        assert!(DepthImage::render(&two_plates(), 0.02, 0.75, &at(0.5)).is_none());
    }
}
