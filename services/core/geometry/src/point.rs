//! The timestamped lidar point shared by every service.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// One lidar return.
///
/// `#[repr(C)]` with no padding (24 bytes) so the same type can travel as a
/// zero-copy slice between processes. Coordinates are in metres in the frame
/// of the cloud that holds the point (the sensor frame for raw frames);
/// `t` is the acquisition time in seconds on the sensor clock.
#[repr(C)]
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Default,
    Serialize,
    Deserialize,
    bytemuck::Pod,
    bytemuck::Zeroable,
)]
pub struct Point {
    /// x coordinate (m).
    pub x: f32,
    /// y coordinate (m).
    pub y: f32,
    /// z coordinate (m).
    pub z: f32,
    /// Return intensity, arbitrary units (non-negative).
    pub intensity: f32,
    /// Acquisition time of this point (s, sensor clock).
    pub t: f64,
}

impl Point {
    /// A point at `(x, y, z)` with intensity and timestamp.
    pub fn new(x: f32, y: f32, z: f32, intensity: f32, t: f64) -> Self {
        Self {
            x,
            y,
            z,
            intensity,
            t,
        }
    }

    /// A point from a double-precision position.
    pub fn from_vector(v: &Vector3<f64>, intensity: f32, t: f64) -> Self {
        Self {
            x: v.x as f32,
            y: v.y as f32,
            z: v.z as f32,
            intensity,
            t,
        }
    }

    /// The position in double precision.
    #[inline]
    pub fn position(&self) -> Vector3<f64> {
        Vector3::new(self.x as f64, self.y as f64, self.z as f64)
    }

    /// True when position, intensity and timestamp are all finite.
    #[inline]
    pub fn is_finite(&self) -> bool {
        self.x.is_finite()
            && self.y.is_finite()
            && self.z.is_finite()
            && self.intensity.is_finite()
            && self.t.is_finite()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_is_24_bytes_without_padding() {
        assert_eq!(std::mem::size_of::<Point>(), 24);
        assert_eq!(std::mem::align_of::<Point>(), 8);
    }

    #[test]
    fn finiteness_checks_every_field() {
        assert!(Point::new(1.0, 2.0, 3.0, 0.5, 1.0).is_finite());
        assert!(!Point::new(f32::NAN, 2.0, 3.0, 0.5, 1.0).is_finite());
        assert!(!Point::new(1.0, 2.0, 3.0, 0.5, f64::INFINITY).is_finite());
    }
}
