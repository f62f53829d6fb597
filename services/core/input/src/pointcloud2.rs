//! ROS 2 `sensor_msgs/msg/PointCloud2` messages (CDR) to points.
//!
//! Rules: big-endian CDR or `is_bigendian` data are refused; `x y z` must
//! be FLOAT32 or FLOAT64; the time field may be any numeric type; every
//! field of known type must fit in `point_step`; the rows must fit in
//! `data`. With `is_dense = false`, points with a non-finite position are
//! dropped and counted.
//!
//! Times: the header stamp is taken as the scan start. Relative field times
//! are added to it; the scan interval is the span of the point times. With
//! no time field, times are derived over `[stamp, stamp + scan period]`.

use crate::cdr::CdrReader;
use crate::error::CloudError;
use crate::frame::{ScanTimeSource, time_span};
use crate::options::InputOptions;
use crate::packed::{PackedField, PackedLayout, unpack};
use crate::scalar::Scalar;
use spacepose_geometry::{Point, PointTimes};

/// Schema name of the message.
pub const SCHEMA_NAME: &str = "sensor_msgs/msg/PointCloud2";

/// A decoded point-cloud message, before it becomes a frame.
#[derive(Debug)]
pub(crate) struct DecodedCloud {
    /// Points, `t` absolute (s).
    pub points: Vec<Point>,
    /// Where the point times came from.
    pub point_times: PointTimes,
    /// Scan interval (s).
    pub scan_s: (f64, f64),
    /// Where it came from.
    pub scan_time_source: ScanTimeSource,
    /// Non-finite points dropped.
    pub dropped_non_finite: usize,
    /// The message's coordinate frame name.
    pub frame_id: String,
}

/// A parsed message: its stamp, layout and borrowed data.
#[derive(Debug)]
pub(crate) struct PointCloud2<'a> {
    /// `header.stamp` (s).
    pub stamp_s: f64,
    /// `header.frame_id`.
    pub frame_id: String,
    /// Field layout.
    pub layout: PackedLayout,
    /// Point data.
    pub data: &'a [u8],
    /// `is_dense`.
    pub is_dense: bool,
}

/// Parses the CDR of a PointCloud2.
///
/// # Errors
/// [`CloudError`] for truncation, big-endian data or encapsulation.
pub(crate) fn parse(message: &[u8]) -> Result<PointCloud2<'_>, CloudError> {
    let mut r = CdrReader::new(message)?;
    let sec = r.i32("header.stamp.sec")?;
    let nanosec = r.u32("header.stamp.nanosec")?;
    let frame_id = r.string("header.frame_id")?;
    let height = r.u32("height")?;
    let width = r.u32("width")?;
    let n_fields = r.u32("fields")?;
    let mut fields = Vec::new();
    for _ in 0..n_fields {
        let name = r.string("fields[].name")?;
        let offset = r.u32("fields[].offset")?;
        let datatype = r.u8("fields[].datatype")?;
        let count = r.u32("fields[].count")?;
        fields.push(PackedField {
            name,
            offset,
            scalar: Scalar::from_ros(datatype),
            code: u32::from(datatype),
            count,
        });
    }
    let is_bigendian = r.u8("is_bigendian")? != 0;
    let point_step = r.u32("point_step")?;
    let row_step = r.u32("row_step")?;
    let data = r.bytes("data")?;
    let is_dense = r.u8("is_dense")? != 0;
    if is_bigendian {
        return Err(CloudError::BigEndian("point data (is_bigendian)"));
    }
    Ok(PointCloud2 {
        stamp_s: f64::from(sec) + f64::from(nanosec) * 1e-9,
        frame_id,
        layout: PackedLayout {
            fields,
            height,
            width,
            point_step,
            row_step,
        },
        data,
        is_dense,
    })
}

/// Decodes a PointCloud2 into points with absolute times.
///
/// # Errors
/// As [`parse`] and [`unpack`].
pub(crate) fn decode(message: &[u8], options: &InputOptions) -> Result<DecodedCloud, CloudError> {
    let cloud = parse(message)?;
    let unpacked = unpack(&cloud.layout, cloud.data, &options.time, !cloud.is_dense)?;
    let stamp_s = cloud.stamp_s;
    let derived_s = (stamp_s, stamp_s + options.scan_period_or(None));
    let (points, point_times) = unpacked.cloud.into_absolute(stamp_s, derived_s);
    let mut decoded = finish(points, point_times, derived_s, unpacked.dropped_non_finite);
    decoded.frame_id = cloud.frame_id;
    Ok(decoded)
}

/// The scan interval: the span of field times, else `fallback_s`.
pub(crate) fn finish(
    points: Vec<Point>,
    point_times: PointTimes,
    fallback_s: (f64, f64),
    dropped_non_finite: usize,
) -> DecodedCloud {
    let span = match point_times {
        PointTimes::Field(_) => time_span(&points),
        PointTimes::Derived => None,
    };
    let (scan_s, scan_time_source) = match span {
        Some(s) => (s, ScanTimeSource::PointTimes),
        None => (fallback_s, ScanTimeSource::ScanPeriod),
    };
    DecodedCloud {
        points,
        point_times,
        scan_s,
        scan_time_source,
        dropped_non_finite,
        frame_id: String::new(),
    }
}

#[cfg(test)]
#[path = "pointcloud2_tests.rs"]
mod tests;
