//! PCD v0.7 files (the Point Cloud Library format) of [`Point`]s.
//!
//! Reading uses `pcd-rs` 0.13 (header parsing and `ascii` / `binary` /
//! `binary_compressed` decoding of dynamic schemas) behind a validation
//! layer. The layer exists because `pcd-rs` trusts header numbers for
//! allocations: a `_` padding field with a huge `COUNT` or a lying
//! `binary_compressed` size prefix makes it allocate gigabytes or index out of
//! bounds. We therefore parse the header once, bound every field count and
//! the record size, check that the binary payload is as long as the header
//! promises and that compressed sizes are consistent, and only then let
//! `pcd-rs` decode.
//!
//! Writing is done here by hand rather than with `pcd_rs::Writer`: that writer
//! panics in `Drop` unless `finish()` completed, so any I/O error while
//! writing turns into a panic, and it allocates per field per point. The
//! header is ten lines and the payload a loop.

use std::io::{Cursor, Write};
use std::path::Path;

use pcd_rs::{DataKind, DynReader, DynRecord, Field, PcdMeta, ValueKind};

use super::fields::{Issue, Role, io_error};
use super::time::{TimeMapping, TimedCloud};
use crate::error::GeometryError;
use crate::point::Point;

const FORMAT: &str = "PCD";
/// Largest `COUNT` accepted for one field (PCL feature histograms use ~300).
const MAX_FIELD_COUNT: u64 = 4096;
/// Largest LZF expansion ratio (a 3-byte back reference yields at most 264 bytes).
const MAX_LZF_RATIO: usize = 88;

/// The `DATA` encoding to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PcdEncoding {
    /// One text line per point.
    Ascii,
    /// Packed little-endian records.
    Binary,
}

/// Reads a PCD file (`DATA ascii`, `binary` or `binary_compressed`).
///
/// # Errors
/// [`GeometryError::Io`] if the file cannot be read,
/// [`GeometryError::Malformed`] for corrupt or truncated content,
/// [`GeometryError::Unsupported`] for e.g. integer coordinates.
pub fn read_pcd(path: impl AsRef<Path>) -> Result<Vec<Point>, GeometryError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(io_error(path))?;
    parse_pcd(&bytes).map_err(|issue| issue.at(path, FORMAT))
}

/// Reads a PCD file with the time field chosen by `mapping` (raw values in
/// `t`, unconverted; see [`super::read_cloud_timed`]).
pub(crate) fn read_pcd_timed(
    path: &Path,
    mapping: &TimeMapping,
) -> Result<TimedCloud, GeometryError> {
    let bytes = std::fs::read(path).map_err(io_error(path))?;
    parse_pcd_timed(&bytes, mapping).map_err(|issue| issue.at(path, FORMAT))
}

/// Writes `points` as PCD v0.7 with fields `x y z t intensity`
/// (`t` as 64-bit float, the rest 32-bit).
///
/// # Errors
/// [`GeometryError::Io`] if the file cannot be written.
pub fn write_pcd(
    path: impl AsRef<Path>,
    points: &[Point],
    encoding: PcdEncoding,
) -> Result<(), GeometryError> {
    let path = path.as_ref();
    let bytes = encode_pcd(points, encoding).map_err(io_error(path))?;
    std::fs::write(path, bytes).map_err(io_error(path))
}

/// Serialises a cloud; only fails if formatting into memory fails.
fn encode_pcd(points: &[Point], encoding: PcdEncoding) -> std::io::Result<Vec<u8>> {
    let mut out = Vec::with_capacity(256 + points.len() * 28);
    let n = points.len();
    let data = match encoding {
        PcdEncoding::Ascii => "ascii",
        PcdEncoding::Binary => "binary",
    };
    write!(
        out,
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z t intensity\n\
         SIZE 4 4 4 8 4\nTYPE F F F F F\nCOUNT 1 1 1 1 1\nWIDTH {n}\nHEIGHT 1\n\
         VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {data}\n"
    )?;
    for p in points {
        match encoding {
            // `Display` prints the shortest string that parses back to the same bits.
            PcdEncoding::Ascii => writeln!(out, "{} {} {} {} {}", p.x, p.y, p.z, p.t, p.intensity)?,
            PcdEncoding::Binary => {
                out.extend_from_slice(&p.x.to_le_bytes());
                out.extend_from_slice(&p.y.to_le_bytes());
                out.extend_from_slice(&p.z.to_le_bytes());
                out.extend_from_slice(&p.t.to_le_bytes());
                out.extend_from_slice(&p.intensity.to_le_bytes());
            }
        }
    }
    Ok(out)
}

/// Where each [`Point`] field sits in a `pcd-rs` record (padding skipped).
#[derive(Debug, Default)]
struct Layout {
    /// `(index in DynRecord, role)` for every field we read.
    slots: Vec<(usize, Role)>,
    /// Bytes of one binary record, padding included.
    record_bytes: usize,
}

/// The plain reader: time in `t`, a float.
fn parse_pcd(bytes: &[u8]) -> Result<Vec<Point>, Issue> {
    decode_pcd(bytes, |_| Ok(TimeChoice::PLAIN))
}

fn parse_pcd_timed(bytes: &[u8], mapping: &TimeMapping) -> Result<TimedCloud, Issue> {
    let mut time = None;
    let points = decode_pcd(bytes, |meta| {
        let fields = meta.field_defs.iter().map(|d| {
            let integer = !matches!(d.kind, ValueKind::F32 | ValueKind::F64);
            (d.name.as_str(), integer)
        });
        time = mapping.resolve(fields).map_err(Issue::Unsupported)?;
        Ok(TimeChoice {
            name: time.as_ref().map_or(String::new(), |f| f.name.clone()),
            any_numeric: true,
        })
    })?;
    Ok(TimedCloud { points, time })
}

/// Which field is the time, and whether it may be an integer.
struct TimeChoice {
    name: String,
    any_numeric: bool,
}

impl TimeChoice {
    const PLAIN: TimeChoice = TimeChoice {
        name: String::new(),
        any_numeric: false,
    };

    fn name(&self) -> &str {
        if self.name.is_empty() && !self.any_numeric {
            "t"
        } else {
            &self.name
        }
    }
}

fn decode_pcd(
    bytes: &[u8],
    choose_time: impl FnOnce(&PcdMeta) -> Result<TimeChoice, Issue>,
) -> Result<Vec<Point>, Issue> {
    let mut cursor = Cursor::new(bytes);
    let meta = PcdMeta::from_reader(&mut cursor).map_err(malformed)?;
    let header_len = cursor.position() as usize;
    let layout = layout_of(&meta, &choose_time(&meta)?)?;
    let payload = bytes.get(header_len..).unwrap_or_default();
    let capacity = check_payload_size(&meta, &layout, payload)?;

    let reader = DynReader::from_bytes(bytes).map_err(malformed)?;
    let mut points = Vec::with_capacity(capacity);
    for record in reader {
        let record = record.map_err(|e| {
            Issue::Malformed(format!(
                "point {} of {}: {e}",
                points.len(),
                meta.num_points
            ))
        })?;
        points.push(point_of(&record, &layout)?);
    }
    if points.len() as u64 != meta.num_points {
        return Err(Issue::Malformed(format!(
            "header promises {} points, data holds {}",
            meta.num_points,
            points.len()
        )));
    }
    Ok(points)
}

/// Maps fields to roles and bounds the record size.
fn layout_of(meta: &PcdMeta, time: &TimeChoice) -> Result<Layout, Issue> {
    let mut layout = Layout::default();
    let mut index = 0;
    for def in meta.field_defs.iter() {
        if def.count > MAX_FIELD_COUNT {
            return Err(Issue::Unsupported(format!(
                "field {:?} has COUNT {} (limit {MAX_FIELD_COUNT})",
                def.name, def.count
            )));
        }
        let field_bytes = def.kind.byte_size() * def.count as usize;
        layout.record_bytes = layout
            .record_bytes
            .checked_add(field_bytes)
            .ok_or_else(|| Issue::Malformed("record size overflows".into()))?;
        if def.is_padding() {
            continue; // pcd-rs drops padding from the record
        }
        if let Some(role) = Role::of(&def.name, time.name()) {
            check_field_type(role, &def.name, def.kind, def.count, time.any_numeric)?;
            layout.slots.push((index, role));
        }
        index += 1;
    }
    for (role, name) in [(Role::X, "x"), (Role::Y, "y"), (Role::Z, "z")] {
        if !layout.slots.iter().any(|&(_, r)| r == role) {
            return Err(Issue::Malformed(format!("no {name} field")));
        }
    }
    Ok(layout)
}

fn check_field_type(
    role: Role,
    name: &str,
    kind: ValueKind,
    count: u64,
    any_numeric_time: bool,
) -> Result<(), Issue> {
    if count != 1 {
        return Err(Issue::Unsupported(format!(
            "field {name:?} has COUNT {count}, expected 1"
        )));
    }
    let is_float = matches!(kind, ValueKind::F32 | ValueKind::F64);
    let any_numeric = role == Role::Intensity || (role == Role::T && any_numeric_time);
    if !any_numeric && !is_float {
        return Err(Issue::Unsupported(format!(
            "field {name:?} is {kind:?}; positions and t must be F 4 or F 8"
        )));
    }
    Ok(())
}

/// Checks that the payload can hold what the header declares; returns a safe
/// pre-allocation size for the point vector.
fn check_payload_size(meta: &PcdMeta, layout: &Layout, payload: &[u8]) -> Result<usize, Issue> {
    let n = usize::try_from(meta.num_points)
        .map_err(|_| Issue::Malformed(format!("absurd POINTS {}", meta.num_points)))?;
    let needed = n.checked_mul(layout.record_bytes);
    match meta.data {
        DataKind::Ascii => Ok(n.min(payload.len() / 2)),
        DataKind::Binary => match needed {
            Some(needed) if needed <= payload.len() => Ok(n),
            _ => Err(Issue::Malformed(format!(
                "truncated binary data: {n} points of {} bytes need more than the {} bytes present",
                layout.record_bytes,
                payload.len()
            ))),
        },
        DataKind::BinaryCompressed => {
            check_compressed_sizes(needed, payload)?;
            Ok(n)
        }
    }
}

/// Validates the `compressed_size uncompressed_size` prefix of
/// `binary_compressed` data before `pcd-rs` allocates from it.
fn check_compressed_sizes(needed: Option<usize>, payload: &[u8]) -> Result<(), Issue> {
    let word = |i: usize| {
        payload
            .get(i..i + 4)
            .and_then(|b| b.try_into().ok())
            .map(|b: [u8; 4]| u32::from_le_bytes(b) as usize)
            .ok_or_else(|| Issue::Malformed("truncated binary_compressed size prefix".into()))
    };
    let (compressed, uncompressed) = (word(0)?, word(4)?);
    if compressed > payload.len() - 8 {
        return Err(Issue::Malformed(format!(
            "truncated binary_compressed data: {compressed} bytes announced, {} present",
            payload.len() - 8
        )));
    }
    if needed != Some(uncompressed) || uncompressed > compressed.saturating_mul(MAX_LZF_RATIO) {
        return Err(Issue::Malformed(format!(
            "binary_compressed size {uncompressed} inconsistent with the header \
             ({needed:?} bytes) or with {compressed} compressed bytes"
        )));
    }
    Ok(())
}

fn point_of(record: &DynRecord, layout: &Layout) -> Result<Point, Issue> {
    let mut p = Point::default();
    for &(index, role) in &layout.slots {
        let value = record
            .0
            .get(index)
            .and_then(scalar_of)
            .ok_or_else(|| Issue::Malformed("record shorter than its header".into()))?;
        role.set(&mut p, value);
    }
    Ok(p)
}

/// The single value of a `COUNT 1` field, widened to `f64` (exact for every
/// type we accept for positions and `t`; intensity integers beyond 2^53 round).
fn scalar_of(field: &Field) -> Option<f64> {
    match field {
        Field::F32(v) => v.first().map(|&x| x as f64),
        Field::F64(v) => v.first().copied(),
        Field::U8(v) => v.first().map(|&x| x as f64),
        Field::U16(v) => v.first().map(|&x| x as f64),
        Field::U32(v) => v.first().map(|&x| x as f64),
        Field::U64(v) => v.first().map(|&x| x as f64),
        Field::I8(v) => v.first().map(|&x| x as f64),
        Field::I16(v) => v.first().map(|&x| x as f64),
        Field::I32(v) => v.first().map(|&x| x as f64),
        Field::I64(v) => v.first().map(|&x| x as f64),
    }
}

fn malformed(e: pcd_rs::Error) -> Issue {
    Issue::Malformed(e.to_string())
}

#[cfg(test)]
#[path = "pcd_tests.rs"]
mod tests;
