//! Point-cloud frames: a fixed `#[repr(C)]` header plus a slice of points.
//!
//! On iceoryx2 a frame is the payload `[WirePoint]` with the user header
//! [`CloudHeader`]; on zenoh it is a [`CloudMsg`] in the postcard codec.

use crate::SCHEMA_VERSION;
use crate::codec::{CodecError, WireMessage, fixed_max_wire_bytes};
use bytemuck::{Pod, Zeroable};
use iceoryx2::prelude::ZeroCopySend;
use serde::{Deserialize, Serialize};
use spacepose_geometry::Point;

/// Capacity of a cloud slice (points); larger frames are rejected and counted.
pub const MAX_POINTS: usize = 200_000;

/// Header of one lidar frame (iceoryx2 user header of the cloud services).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, Serialize, Deserialize)]
#[type_name("spacepose::CloudHeader")]
pub struct CloudHeader {
    /// Schema version of the sender ([`SCHEMA_VERSION`]).
    pub schema: u16,
    /// Sensor identifier (0 for the single lidar).
    pub sensor_id: u16,
    /// Number of points in the frame (set by the bus on send).
    pub point_count: u32,
    /// Frame counter of the sensor (monotonic, starts at 0).
    pub sequence: u64,
    /// Time of the first point of the scan (s, sensor clock).
    pub scan_start_s: f64,
    /// Time of the last point of the scan (s, sensor clock).
    pub scan_end_s: f64,
    /// CLOCK_REALTIME at send (ns since the Unix epoch), for latency.
    pub published_ns: i64,
}

impl CloudHeader {
    /// A header for frame `sequence` covering `[scan_start_s, scan_end_s]`.
    pub fn new(sequence: u64, scan_start_s: f64, scan_end_s: f64) -> Self {
        Self {
            schema: SCHEMA_VERSION,
            sequence,
            scan_start_s,
            scan_end_s,
            ..Self::default()
        }
    }
}

/// One point on the wire: the exact layout of [`spacepose_geometry::Point`]
/// (24 bytes, `#[repr(C)]`, no padding), so slices cast without copying.
#[repr(C)]
#[derive(
    Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, Pod, Zeroable, Serialize, Deserialize,
)]
#[type_name("spacepose::WirePoint")]
pub struct WirePoint {
    /// x coordinate (m, frame of the cloud: sensor frame for raw frames).
    pub x: f32,
    /// y coordinate (m).
    pub y: f32,
    /// z coordinate (m).
    pub z: f32,
    /// Return intensity (arbitrary units, non-negative).
    pub intensity: f32,
    /// Acquisition time of the point (s, sensor clock).
    pub t: f64,
}

/// Views wire points as geometry points (zero copy).
pub fn as_points(wire: &[WirePoint]) -> &[Point] {
    bytemuck::cast_slice(wire)
}

/// Views geometry points as wire points (zero copy).
pub fn as_wire(points: &[Point]) -> &[WirePoint] {
    bytemuck::cast_slice(points)
}

impl From<Point> for WirePoint {
    fn from(p: Point) -> Self {
        bytemuck::cast(p)
    }
}

impl From<WirePoint> for Point {
    fn from(w: WirePoint) -> Self {
        bytemuck::cast(w)
    }
}

/// A whole frame as one value, for zenoh (postcard) and tests.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CloudMsg {
    /// The frame header; `point_count` equals `points.len()`.
    pub header: CloudHeader,
    /// The points (frame of the header's cloud).
    pub points: Vec<Point>,
}

impl CloudMsg {
    /// A frame from a header and points (sets `schema` and `point_count`).
    pub fn new(mut header: CloudHeader, points: Vec<Point>) -> Self {
        header.schema = SCHEMA_VERSION;
        header.point_count = u32::try_from(points.len()).unwrap_or(u32::MAX);
        Self { header, points }
    }
}

impl WireMessage for CloudMsg {
    const KIND: u8 = 1;
    // header + varint length + 24 bytes per point (postcard writes floats as fixed LE).
    const MAX_WIRE_BYTES: usize = fixed_max_wire_bytes::<CloudHeader>() + 10 + MAX_POINTS * 24;

    fn schema(&self) -> u16 {
        self.header.schema
    }

    fn validate(&self) -> Result<(), CodecError> {
        if self.points.len() > MAX_POINTS {
            return Err(CodecError::Invalid(format!(
                "{} points > MAX_POINTS {MAX_POINTS}",
                self.points.len()
            )));
        }
        if self.header.point_count as usize != self.points.len() {
            return Err(CodecError::Invalid(format!(
                "point_count {} but {} points",
                self.header.point_count,
                self.points.len()
            )));
        }
        Ok(())
    }

    fn set_published_ns(&mut self, ns: i64) {
        self.header.published_ns = ns;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::{align_of, offset_of, size_of};

    #[test]
    fn wire_point_has_the_layout_of_point() {
        assert_eq!(size_of::<WirePoint>(), 24);
        assert_eq!(size_of::<WirePoint>(), size_of::<Point>());
        assert_eq!(align_of::<WirePoint>(), align_of::<Point>());
        assert_eq!(offset_of!(WirePoint, x), offset_of!(Point, x));
        assert_eq!(offset_of!(WirePoint, y), offset_of!(Point, y));
        assert_eq!(offset_of!(WirePoint, z), offset_of!(Point, z));
        assert_eq!(
            offset_of!(WirePoint, intensity),
            offset_of!(Point, intensity)
        );
        assert_eq!(offset_of!(WirePoint, t), offset_of!(Point, t));
    }

    #[test]
    fn casts_are_zero_copy_and_keep_values() {
        let points: Vec<Point> = (0..100)
            .map(|i| Point::new(i as f32, -(i as f32), 0.5 * i as f32, 0.25, 1e-3 * i as f64))
            .collect();
        let wire = as_wire(&points);
        assert_eq!(wire.len(), points.len());
        assert_eq!(wire.as_ptr() as usize, points.as_ptr() as usize);
        for (w, p) in wire.iter().zip(&points) {
            assert_eq!(
                (w.x, w.y, w.z, w.intensity, w.t),
                (p.x, p.y, p.z, p.intensity, p.t)
            );
        }
        let back = as_points(wire);
        assert_eq!(back, &points[..]);
    }

    #[test]
    fn cloud_header_layout_is_stable() {
        // 2 + 2 + 4 + 8 + 8 + 8 + 8: no padding, so every byte is meaningful.
        assert_eq!(size_of::<CloudHeader>(), 40);
    }
}
