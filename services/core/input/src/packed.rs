//! Points packed in a byte buffer by a field layout (ROS 2 PointCloud2,
//! Foxglove PointCloud): checked against the buffer, then read into
//! [`Point`]s with the time field of the [`TimeMapping`].

use crate::error::CloudError;
use crate::scalar::Scalar;
use spacepose_geometry::{Point, TimeMapping, TimedCloud};

/// One field of a packed point.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PackedField {
    /// Field name.
    pub name: String,
    /// Byte offset in the point.
    pub offset: u32,
    /// Its type; `None` for a code we do not know (an error only if the field is used).
    pub scalar: Option<Scalar>,
    /// Raw type code, for error messages.
    pub code: u32,
    /// Values per point.
    pub count: u32,
}

/// How points are packed: `height` rows of `width` points.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PackedLayout {
    /// The fields.
    pub fields: Vec<PackedField>,
    /// Rows.
    pub height: u32,
    /// Points per row.
    pub width: u32,
    /// Bytes per point.
    pub point_step: u32,
    /// Bytes per row.
    pub row_step: u32,
}

/// Points read from a buffer.
#[derive(Debug)]
pub(crate) struct Unpacked {
    /// Points, `t` in seconds as the time field says (NaN without one).
    pub cloud: TimedCloud,
    /// Non-finite points dropped.
    pub dropped_non_finite: usize,
}

/// A used field: where it is and how to read it.
#[derive(Debug, Clone, Copy)]
struct Slot {
    offset: usize,
    scalar: Scalar,
}

/// Reads every point of `data`; drops points with a non-finite position
/// when `drop_non_finite` (PointCloud2 with `is_dense = false`).
///
/// # Errors
/// [`CloudError`] for a missing or mistyped coordinate, a field outside the
/// point, an unknown type on a used field, or data shorter than the layout.
pub(crate) fn unpack(
    layout: &PackedLayout,
    data: &[u8],
    mapping: &TimeMapping,
    drop_non_finite: bool,
) -> Result<Unpacked, CloudError> {
    check_extents(layout, data.len())?;
    let xyz = [
        coordinate(layout, "x")?,
        coordinate(layout, "y")?,
        coordinate(layout, "z")?,
    ];
    let intensity = optional_slot(layout, "intensity")?;
    let known = layout
        .fields
        .iter()
        .filter_map(|f| Some((f.name.as_str(), f.scalar?.is_integer())));
    let time = mapping.resolve(known).map_err(CloudError::TimeField)?;
    let time_slot = match &time {
        Some(f) => optional_slot(layout, &f.name)?,
        None => None,
    };
    let scale = time
        .as_ref()
        .map_or(f64::NAN, |f| f.unit.seconds_per_unit());
    let read = |point: &[u8], s: Slot| s.scalar.read_le(&point[s.offset..]).unwrap_or(f64::NAN);
    let mut points = Vec::with_capacity(layout.width as usize * layout.height as usize);
    let mut dropped = 0;
    let rows = if layout.width == 0 { 0 } else { layout.height };
    for row in 0..rows as usize {
        let row_start = row * layout.row_step as usize;
        for col in 0..layout.width as usize {
            let start = row_start + col * layout.point_step as usize;
            let point = &data[start..start + layout.point_step as usize];
            let p = Point {
                x: read(point, xyz[0]) as f32,
                y: read(point, xyz[1]) as f32,
                z: read(point, xyz[2]) as f32,
                intensity: intensity.map_or(0.0, |s| read(point, s) as f32),
                t: time_slot.map_or(f64::NAN, |s| read(point, s) * scale),
            };
            if drop_non_finite && !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                dropped += 1;
            } else {
                points.push(p);
            }
        }
    }
    Ok(Unpacked {
        cloud: TimedCloud { points, time },
        dropped_non_finite: dropped,
    })
}

/// Rows fit the data, points fit the rows, known fields fit the points.
fn check_extents(layout: &PackedLayout, data_len: usize) -> Result<(), CloudError> {
    let (w, h) = (u64::from(layout.width), u64::from(layout.height));
    let (step, row) = (u64::from(layout.point_step), u64::from(layout.row_step));
    if w * step > row {
        return Err(CloudError::FieldType {
            name: "row_step".into(),
            message: format!("{w} points of {step} bytes do not fit a row of {row} bytes"),
        });
    }
    let needed = if h == 0 {
        0
    } else {
        ((h - 1).saturating_mul(row)).saturating_add(w * step)
    };
    if needed > data_len as u64 {
        return Err(CloudError::DataTooShort {
            needed,
            present: data_len as u64,
        });
    }
    for f in &layout.fields {
        let Some(scalar) = f.scalar else { continue };
        let size = u64::from(scalar.size()) * u64::from(f.count);
        if u64::from(f.offset) + size > step {
            return Err(CloudError::FieldOutsidePoint {
                name: f.name.clone(),
                offset: f.offset,
                size: u32::try_from(size).unwrap_or(u32::MAX),
                point_step: layout.point_step,
            });
        }
    }
    Ok(())
}

/// A used field by name: known type, one value.
fn optional_slot(layout: &PackedLayout, name: &str) -> Result<Option<Slot>, CloudError> {
    let Some(f) = layout.fields.iter().find(|f| f.name == name) else {
        return Ok(None);
    };
    let scalar = f.scalar.ok_or_else(|| CloudError::Datatype {
        name: f.name.clone(),
        datatype: f.code,
    })?;
    if f.count != 1 {
        return Err(CloudError::FieldType {
            name: f.name.clone(),
            message: format!("count {} (one value per point expected)", f.count),
        });
    }
    Ok(Some(Slot {
        offset: f.offset as usize,
        scalar,
    }))
}

/// A coordinate field: present, FLOAT32 or FLOAT64.
fn coordinate(layout: &PackedLayout, name: &'static str) -> Result<Slot, CloudError> {
    let slot = optional_slot(layout, name)?.ok_or(CloudError::MissingField(name))?;
    if slot.scalar.is_integer() {
        return Err(CloudError::FieldType {
            name: name.into(),
            message: format!("{:?}; coordinates must be FLOAT32 or FLOAT64", slot.scalar),
        });
    }
    Ok(slot)
}
