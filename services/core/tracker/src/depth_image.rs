//! The model's depth image at a predicted pose: for each direction from the
//! sensor, the range of the nearest model surface (a z-buffer of the model
//! cloud), and that image widened to the farthest first surface within a
//! neighbourhood. [`crate::visibility`] uses it to find the points that lie
//! behind every surface the model can show there.
//!
//! Directions are pixels of the plane tangent to the line of sight to the
//! target's origin (`u = x·e₁ / x·l`, `v = x·e₂ / x·l`), so any sensor
//! geometry works. The pixel is twice the model cloud's spacing seen from
//! the nearest point of the target's bounding sphere, so that every pixel
//! the model covers holds at least one model point: an empty pixel inside
//! the silhouette would read as "no surface" and keep the points behind it.

use nalgebra::Vector3;
use spacepose_geometry::Pose;

/// Largest image side (pixels): beyond it the pixel grows instead.
const MAX_SIDE: usize = 512;

/// A depth image of a model cloud, widened by a neighbourhood maximum.
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
    /// Per pixel, the farthest nearest-surface range within the
    /// neighbourhood (m); +∞ where no pixel of the neighbourhood holds a
    /// model surface.
    far: Vec<f32>,
}

impl DepthImage {
    /// The image of `model_target` (body frame, sampled every `spacing_m`,
    /// inside a sphere of `radius_m` about the origin) seen at
    /// `t_sensor_target`, widened by `margin_m` of surface displacement.
    /// `None` when the sensor is inside the bounding sphere (no tangent
    /// plane holds the target).
    pub fn render(
        model_target: &[Vector3<f64>],
        spacing_m: f64,
        radius_m: f64,
        t_sensor_target: &Pose,
        margin_m: f64,
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
            far: vec![f32::INFINITY; side * side],
        };
        let mut near = vec![f32::INFINITY; side * side];
        for m in model_target {
            let x = t_sensor_target.transform(m);
            if let Some(i) = image.pixel_of(&x) {
                near[i] = near[i].min(x.norm() as f32);
            }
        }
        // Angular displacement of the surface nearest the sensor, in pixels.
        let k = (margin_m / nearest / pixel).ceil().max(1.0) as usize;
        image.far = widen(&near, side, k);
        Some(image)
    }

    /// The pixel index of a sensor-frame position, `None` outside the image
    /// or behind the sensor's plane through the origin.
    fn pixel_of(&self, x: &Vector3<f64>) -> Option<usize> {
        let d = x.dot(&self.l);
        if d <= 0.0 {
            return None;
        }
        let u = ((x.dot(&self.e1) / d - self.origin) / self.pixel).floor();
        let v = ((x.dot(&self.e2) / d - self.origin) / self.pixel).floor();
        let side = self.side as f64;
        if !(u >= 0.0 && v >= 0.0 && u < side && v < side) {
            return None;
        }
        Some(v as usize * self.side + u as usize)
    }

    /// The farthest range (m) at which a model surface could be the first
    /// surface along the direction of `x`, within the neighbourhood; +∞
    /// outside the image or where no surface covers the neighbourhood.
    pub fn farthest_first_surface(&self, x: &Vector3<f64>) -> f32 {
        self.pixel_of(x).map_or(f32::INFINITY, |i| self.far[i])
    }

    /// Image side (pixels).
    #[cfg(test)]
    pub fn side(&self) -> usize {
        self.side
    }
}

/// The maximum over the `(2k+1)²` square about each pixel (separable: rows,
/// then columns), over the pixels that hold a surface.
fn widen(near: &[f32], side: usize, k: usize) -> Vec<f32> {
    let pass = |src: &[f32], stride: usize, step: usize| {
        let mut out = vec![0.0f32; src.len()];
        for line in 0..side {
            for j in 0..side {
                let lo = j.saturating_sub(k);
                let hi = (j + k).min(side - 1);
                let mut m = f32::NEG_INFINITY;
                for s in lo..=hi {
                    m = m.max(src[line * stride + s * step]);
                }
                out[line * stride + j * step] = m;
            }
        }
        out
    };
    // An empty pixel takes no part in the maximum: where the ray meets no
    // model surface, no surface return can come from it either. Only a
    // neighbourhood with no surface at all stays open (+∞).
    let surfaces: Vec<f32> = near
        .iter()
        .map(|&d| if d.is_finite() { d } else { f32::NEG_INFINITY })
        .collect();
    let rows = pass(&surfaces, side, 1);
    let mut far = pass(&rows, 1, side);
    for d in &mut far {
        if !d.is_finite() {
            *d = f32::INFINITY;
        }
    }
    far
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
    fn the_first_surface_is_the_near_plate_and_none_outside_the_silhouette() {
        let img = DepthImage::render(&two_plates(), 0.02, 0.75, &at(10.0), 0.05).unwrap();
        let centre = img.farthest_first_surface(&Vector3::new(0.0, 0.0, 10.0));
        assert!((centre - 9.5).abs() < 0.01, "near plate at 9.5 m: {centre}");
        let beside = img.farthest_first_surface(&Vector3::new(2.0, 0.0, 10.0));
        assert_eq!(beside, f32::INFINITY);
        // Near the edge the far plate shows nowhere: the near one bounds it
        // (its range there is √(9.5² + 0.5²) = 9.513 m).
        let edge = img.farthest_first_surface(&Vector3::new(0.49, 0.0, 9.5));
        assert!((edge - 9.513).abs() < 0.01, "{edge}");
        assert!(img.side() > 10 && img.side() < MAX_SIDE);
    }

    #[test]
    fn inside_the_bounding_sphere_there_is_no_image() {
        assert!(DepthImage::render(&two_plates(), 0.02, 0.75, &at(0.5), 0.05).is_none());
    }

    #[test]
    fn widening_takes_the_neighbourhood_maximum_over_surfaces() {
        let mut near = vec![1.0f32; 25];
        near[12] = 3.0;
        near[0] = f32::INFINITY;
        let far = widen(&near, 5, 1);
        assert_eq!(far[6], 3.0);
        assert_eq!(
            far[0], 1.0,
            "an empty pixel does not open the neighbourhood"
        );
        assert_eq!(far[18], 3.0);
        let mut empty = vec![f32::INFINITY; 25];
        empty[24] = 2.0;
        let far = widen(&empty, 5, 1);
        assert_eq!((far[0], far[18]), (f32::INFINITY, 2.0));
    }
}
