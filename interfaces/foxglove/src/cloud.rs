//! Clouds as `foxglove.PointCloud`, and the header recorded beside each.
//!
//! Layout (readers of recordings depend on it): fields `x`, `y`, `z`,
//! `intensity` as FLOAT32 at offsets 0, 4, 8, 12 and `t` as FLOAT64 at 16
//! (the point's absolute sensor-clock time in s, exactly `Point::t`),
//! stride 24 bytes, little-endian: the wire layout of a point. The frame is
//! `sensor`; the timestamp is the scan end.

use crate::stamp::timestamp;
use crate::topics::SENSOR_FRAME;
use foxglove::bytes::Bytes;
use foxglove::messages::packed_element_field::NumericType;
use foxglove::messages::{PackedElementField, PointCloud};
use serde::{Deserialize, Serialize};
use spacepose_geometry::Point;
use spacepose_messages::CloudHeader;

/// Bytes per point in a recorded cloud.
pub const POINT_STRIDE: u32 = 24;

/// The fields of a recorded point: name, offset, type.
const FIELDS: [(&str, u32, NumericType); 5] = [
    ("x", 0, NumericType::Float32),
    ("y", 4, NumericType::Float32),
    ("z", 8, NumericType::Float32),
    ("intensity", 12, NumericType::Float32),
    ("t", 16, NumericType::Float64),
];

/// The `foxglove.PointCloud` of a frame's points, stamped `scan_end_s`.
pub fn point_cloud(points: &[Point], scan_end_s: f64) -> PointCloud {
    point_cloud_every(points, 1, scan_end_s)
}

/// The step that keeps at most `max_points` of `n` points when every
/// step-th point is kept (from the first); `max_points = 0`: no budget (1).
pub fn point_step(n: usize, max_points: usize) -> usize {
    if max_points == 0 || n <= max_points {
        1
    } else {
        n.div_ceil(max_points)
    }
}

/// The `foxglove.PointCloud` of every `step`-th point of a frame (from the
/// first; a step of 0 counts as 1), in the layout of [`point_cloud`].
pub fn point_cloud_every(points: &[Point], step: usize, scan_end_s: f64) -> PointCloud {
    let step = step.max(1);
    let kept = points.len().div_ceil(step);
    let mut data = Vec::with_capacity(kept * POINT_STRIDE as usize);
    for p in points.iter().step_by(step) {
        for f in [p.x, p.y, p.z, p.intensity] {
            data.extend_from_slice(&f.to_le_bytes());
        }
        data.extend_from_slice(&p.t.to_le_bytes());
    }
    PointCloud {
        timestamp: Some(timestamp(scan_end_s)),
        frame_id: SENSOR_FRAME.to_string(),
        pose: None,
        point_stride: POINT_STRIDE,
        fields: FIELDS
            .iter()
            .map(|(name, offset, ty)| PackedElementField {
                name: (*name).to_string(),
                offset: *offset,
                r#type: *ty as i32,
            })
            .collect(),
        data: Bytes::from(data),
    }
}

/// The JSON logged beside each cloud (`<topic>/header`, same log time):
/// what a replay needs to publish the frame exactly as it was.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CloudHeaderRecord {
    /// Frame counter of the sensor.
    pub sequence: u64,
    /// Time of the first point of the scan (s, sensor clock).
    pub scan_start_s: f64,
    /// Time of the last point of the scan (s, sensor clock).
    pub scan_end_s: f64,
    /// Sensor identifier.
    pub sensor_id: u16,
    /// Points in the cloud logged beside it: all the frame's points in a
    /// recording (decimated by frame, never by point), fewer on the live
    /// link when a point budget applies.
    pub point_count: u32,
    /// CLOCK_REALTIME when the frame was published (ns since the Unix epoch).
    pub published_ns: i64,
}

impl CloudHeaderRecord {
    /// The record of a cloud header; `point_count` is the points recorded.
    pub fn new(header: &CloudHeader, point_count: usize) -> Self {
        Self {
            sequence: header.sequence,
            scan_start_s: header.scan_start_s,
            scan_end_s: header.scan_end_s,
            sensor_id: header.sensor_id,
            point_count: u32::try_from(point_count).unwrap_or(u32::MAX),
            published_ns: header.published_ns,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use foxglove::{Decode, Encode};

    fn read_f32(data: &[u8], at: usize) -> f32 {
        f32::from_le_bytes(data[at..at + 4].try_into().unwrap())
    }

    #[test]
    fn a_cloud_round_trips_with_the_documented_layout() {
        let points: Vec<Point> = (0..7)
            .map(|i| {
                let k = i as f32;
                Point::new(k, -k, 0.5 * k, 0.1 * k, 1_000.123_456_789 + 1e-6 * i as f64)
            })
            .collect();
        let cloud = point_cloud(&points, 1_000.2);
        let mut buf = Vec::new();
        cloud.encode(&mut buf).unwrap();
        let back = PointCloud::decode(buf.as_slice()).unwrap();
        assert_eq!(back, cloud);
        assert_eq!(back.frame_id, "sensor");
        assert_eq!(back.point_stride, 24);
        let layout: Vec<(&str, u32, i32)> = back
            .fields
            .iter()
            .map(|f| (f.name.as_str(), f.offset, f.r#type))
            .collect();
        assert_eq!(
            layout,
            [
                ("x", 0, 7),
                ("y", 4, 7),
                ("z", 8, 7),
                ("intensity", 12, 7),
                ("t", 16, 8)
            ]
        );
        assert_eq!(back.data.len(), 24 * points.len());
        for (i, p) in points.iter().enumerate() {
            let at = 24 * i;
            let xyzi: Vec<f32> = (0..4).map(|k| read_f32(&back.data, at + 4 * k)).collect();
            assert_eq!(xyzi, [p.x, p.y, p.z, p.intensity]);
            let t = f64::from_le_bytes(back.data[at + 16..at + 24].try_into().unwrap());
            assert_eq!(t.to_bits(), p.t.to_bits());
        }
        let ts = back.timestamp.unwrap();
        assert_eq!((ts.sec(), ts.nsec()), (1_000, 200_000_000));
    }

    #[test]
    fn a_point_budget_keeps_every_kth_point() {
        let points: Vec<Point> = (0..10)
            .map(|i| Point::new(i as f32, 0.0, 1.0, 0.0, 0.0))
            .collect();
        assert_eq!(point_step(10, 0), 1);
        assert_eq!(point_step(10, 10), 1);
        assert_eq!(point_step(10, 4), 3);
        assert_eq!(point_step(10_001, 2_000), 6);
        for n in [1usize, 7, 4_799, 4_800, 4_801, 100_000] {
            for max in [1, 3, 2_000] {
                let kept = n.div_ceil(point_step(n, max));
                assert!(kept <= max && kept >= max.min(n) / 2, "{n} {max} {kept}");
            }
        }
        let cloud = point_cloud_every(&points, 3, 1.0);
        let xs: Vec<f32> = (0..cloud.data.len() / 24)
            .map(|i| read_f32(&cloud.data, 24 * i))
            .collect();
        assert_eq!(xs, [0.0, 3.0, 6.0, 9.0]);
        assert_eq!(
            point_cloud_every(&points, 0, 1.0),
            point_cloud(&points, 1.0)
        );
    }

    #[test]
    fn the_header_record_keeps_the_scan_interval() {
        let mut h = CloudHeader::new(41, 3.5, 3.6);
        h.sensor_id = 2;
        h.published_ns = 17;
        let json = serde_json::to_value(CloudHeaderRecord::new(&h, 9)).unwrap();
        assert_eq!(
            json,
            serde_json::json!({"sequence": 41, "scan_start_s": 3.5, "scan_end_s": 3.6,
                "sensor_id": 2, "point_count": 9, "published_ns": 17})
        );
    }
}
