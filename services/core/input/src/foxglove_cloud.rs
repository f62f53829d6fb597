//! Foxglove `foxglove.PointCloud` messages (protobuf) to points.
//!
//! Any field types of its `NumericType` enum are read; time from the
//! [`spacepose_geometry::TimeMapping`] as for PointCloud2, relative times
//! added to the message timestamp. Non-finite points are kept (the format
//! has no `is_dense`; the consumer rejects them).
//!
//! spacepose writes, beside each cloud, a JSON message on `<topic>/header`
//! at the same log time ([`SpaceposeHeader`]); when present it gives the
//! frame's sequence and scan interval, so a recorded run replays exactly.

use crate::error::CloudError;
use crate::frame::ScanTimeSource;
use crate::options::InputOptions;
use crate::packed::{PackedField, PackedLayout, unpack};
use crate::pointcloud2::{DecodedCloud, finish};
use crate::scalar::Scalar;
use foxglove::Decode;
use foxglove::messages::PointCloud;
use serde::Deserialize;

/// Schema name of the message.
pub const SCHEMA_NAME: &str = "foxglove.PointCloud";

/// Suffix of the topic of the JSON headers spacepose logs beside its clouds.
pub const HEADER_TOPIC_SUFFIX: &str = "/header";

/// The JSON header spacepose logs on `<topic>/header` beside each cloud.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
pub struct SpaceposeHeader {
    /// Frame sequence number.
    pub sequence: u64,
    /// Scan start (s, sensor clock).
    pub scan_start_s: f64,
    /// Scan end (s, sensor clock).
    pub scan_end_s: f64,
    /// Sensor id.
    pub sensor_id: u16,
}

/// Parses a `<topic>/header` JSON message.
///
/// # Errors
/// [`CloudError::Decode`] for invalid JSON or non-finite, unordered times.
pub(crate) fn parse_header(message: &[u8]) -> Result<SpaceposeHeader, CloudError> {
    let h: SpaceposeHeader = serde_json::from_slice(message)
        .map_err(|e| CloudError::Decode(format!("spacepose header: {e}")))?;
    if !(h.scan_start_s.is_finite() && h.scan_end_s.is_finite() && h.scan_start_s <= h.scan_end_s) {
        return Err(CloudError::Decode(format!(
            "spacepose header: scan interval [{}, {}] is not finite and ordered",
            h.scan_start_s, h.scan_end_s
        )));
    }
    Ok(h)
}

/// Decodes a Foxglove PointCloud; `header` is its spacepose header, if any.
///
/// # Errors
/// [`CloudError`] for undecodable protobuf or an inconsistent layout.
pub(crate) fn decode(
    message: &[u8],
    header: Option<&SpaceposeHeader>,
    options: &InputOptions,
) -> Result<DecodedCloud, CloudError> {
    let cloud = PointCloud::decode(message).map_err(|e| CloudError::Decode(e.to_string()))?;
    let layout = layout_of(&cloud)?;
    let unpacked = unpack(&layout, &cloud.data, &options.time, false)?;
    let dropped = unpacked.dropped_non_finite;
    if let Some(h) = header {
        let scan_s = (h.scan_start_s, h.scan_end_s);
        let (points, point_times) = unpacked.cloud.into_absolute(h.scan_start_s, scan_s);
        return Ok(DecodedCloud {
            points,
            point_times,
            scan_s,
            scan_time_source: ScanTimeSource::SpaceposeHeader,
            dropped_non_finite: dropped,
            frame_id: cloud.frame_id,
        });
    }
    let stamp_s = cloud
        .timestamp
        .map_or(0.0, |t| f64::from(t.sec()) + f64::from(t.nsec()) * 1e-9);
    let derived_s = (stamp_s, stamp_s + options.scan_period_or(None));
    let (points, point_times) = unpacked.cloud.into_absolute(stamp_s, derived_s);
    let mut decoded = finish(points, point_times, derived_s, dropped);
    decoded.frame_id = cloud.frame_id;
    Ok(decoded)
}

/// One row of `data.len() / point_stride` points.
fn layout_of(cloud: &PointCloud) -> Result<PackedLayout, CloudError> {
    let stride = cloud.point_stride;
    let len = cloud.data.len() as u64;
    if stride == 0 {
        return Err(CloudError::FieldType {
            name: "point_stride".into(),
            message: "is 0".into(),
        });
    }
    let n = len / u64::from(stride);
    if n * u64::from(stride) != len {
        return Err(CloudError::DataTooShort {
            needed: (n + 1) * u64::from(stride),
            present: len,
        });
    }
    let width = u32::try_from(n).map_err(|_| CloudError::DataTooShort {
        needed: u64::from(u32::MAX),
        present: len,
    })?;
    let fields = cloud
        .fields
        .iter()
        .map(|f| PackedField {
            name: f.name.clone(),
            offset: f.offset,
            scalar: Scalar::from_foxglove(f.r#type),
            code: f.r#type as u32,
            count: 1,
        })
        .collect();
    Ok(PackedLayout {
        fields,
        height: 1,
        width,
        point_step: stride,
        row_step: width.saturating_mul(stride),
    })
}

#[cfg(test)]
#[path = "foxglove_cloud_tests.rs"]
mod tests;
