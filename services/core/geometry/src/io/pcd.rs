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

use super::{Issue, Role, io_error};
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

fn parse_pcd(bytes: &[u8]) -> Result<Vec<Point>, Issue> {
    let mut cursor = Cursor::new(bytes);
    let meta = PcdMeta::from_reader(&mut cursor).map_err(malformed)?;
    let header_len = cursor.position() as usize;
    let layout = layout_of(&meta)?;
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
fn layout_of(meta: &PcdMeta) -> Result<Layout, Issue> {
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
        if let Some(role) = Role::of(&def.name) {
            check_field_type(role, &def.name, def.kind, def.count)?;
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

fn check_field_type(role: Role, name: &str, kind: ValueKind, count: u64) -> Result<(), Issue> {
    if count != 1 {
        return Err(Issue::Unsupported(format!(
            "field {name:?} has COUNT {count}, expected 1"
        )));
    }
    let is_float = matches!(kind, ValueKind::F32 | ValueKind::F64);
    if role != Role::Intensity && !is_float {
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
mod tests {
    use super::*;
    use crate::io::test_support::*;

    #[test]
    fn ascii_and_binary_round_trip_bit_exactly() {
        let points = awkward_cloud(300, 9);
        for encoding in [PcdEncoding::Ascii, PcdEncoding::Binary] {
            let bytes = encode_pcd(&points, encoding).unwrap();
            assert_bit_equal(&parse_pcd(&bytes).unwrap(), &points);
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cloud.pcd");
        write_pcd(&path, &points, PcdEncoding::Binary).unwrap();
        assert_bit_equal(&read_pcd(&path).unwrap(), &points);
    }

    #[test]
    fn non_finite_values_and_empty_clouds_round_trip() {
        let points = [Point::new(
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            0.0,
            f64::NAN,
        )];
        for encoding in [PcdEncoding::Ascii, PcdEncoding::Binary] {
            let back = parse_pcd(&encode_pcd(&points, encoding).unwrap()).unwrap();
            assert!(back[0].x.is_nan() && back[0].t.is_nan());
            assert_eq!(back[0].y, f32::INFINITY);
            assert_eq!(back[0].z, f32::NEG_INFINITY);
            assert!(
                parse_pcd(&encode_pcd(&[], encoding).unwrap())
                    .unwrap()
                    .is_empty()
            );
        }
    }

    fn header(fields: &str, size: &str, ty: &str, n: usize, data: &str) -> String {
        let count = vec!["1"; fields.split(' ').count()].join(" ");
        format!(
            "VERSION 0.7\nFIELDS {fields}\nSIZE {size}\nTYPE {ty}\nCOUNT {count}\n\
             WIDTH {n}\nHEIGHT 1\nPOINTS {n}\nDATA {data}\n"
        )
    }

    #[test]
    fn missing_optional_fields_default_to_zero_and_extra_fields_are_ignored() {
        let text = header("x y z rgb", "4 4 4 4", "F F F U", 2, "ascii") + "1 2 3 77\n-4 5.5 6 0\n";
        let points = parse_pcd(text.as_bytes()).unwrap();
        assert_eq!(
            points,
            [
                Point::new(1.0, 2.0, 3.0, 0.0, 0.0),
                Point::new(-4.0, 5.5, 6.0, 0.0, 0.0)
            ]
        );
    }

    #[test]
    fn double_positions_float_time_integer_intensity_and_padding_are_read() {
        let mut bytes = header(
            "_ intensity x y z t",
            "2 2 8 8 8 4",
            "U U F F F F",
            1,
            "binary",
        )
        .into_bytes();
        bytes.extend_from_slice(&[0xAA, 0xBB]);
        bytes.extend_from_slice(&300u16.to_le_bytes());
        for v in [1.5f64, -2.25, 1e3] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        bytes.extend_from_slice(&0.75f32.to_le_bytes());
        let points = parse_pcd(&bytes).unwrap();
        assert_eq!(points, [Point::new(1.5, -2.25, 1000.0, 300.0, 0.75)]);
    }

    #[test]
    fn binary_compressed_files_written_by_pcd_rs_are_read() {
        // The reference compressed file comes from pcd-rs's own writer.
        let mut buf = Cursor::new(Vec::new());
        let schema = [
            ("x", ValueKind::F32, 1),
            ("y", ValueKind::F32, 1),
            ("z", ValueKind::F32, 1),
        ];
        let mut writer: pcd_rs::DynWriter<_> = pcd_rs::WriterInit {
            width: 2,
            height: 1,
            viewpoint: Default::default(),
            data_kind: DataKind::BinaryCompressed,
            schema: Some(schema.into_iter().collect()),
            version: None,
        }
        .build_from_writer(&mut buf)
        .unwrap();
        for v in [1.0f32, 2.0] {
            writer
                .push(&DynRecord(vec![Field::F32(vec![v]); 3]))
                .unwrap();
        }
        writer.finish().unwrap();
        let points = parse_pcd(buf.get_ref()).unwrap();
        assert_eq!(
            points,
            [
                Point::new(1.0, 1.0, 1.0, 0.0, 0.0),
                Point::new(2.0, 2.0, 2.0, 0.0, 0.0)
            ]
        );
        // A lying uncompressed size is rejected before decoding.
        let bytes = buf.into_inner();
        let data_at = bytes
            .windows(22)
            .position(|w| w == b"DATA binary_compressed")
            .unwrap()
            + 23;
        let mut lying = bytes.clone();
        lying[data_at + 4..data_at + 8].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(matches!(parse_pcd(&lying), Err(Issue::Malformed(_))));
    }

    #[test]
    fn truncated_files_are_errors() {
        let points = awkward_cloud(20, 3);
        for encoding in [PcdEncoding::Ascii, PcdEncoding::Binary] {
            let bytes = encode_pcd(&points, encoding).unwrap();
            for len in [0, 10, 60, bytes.len() / 2, bytes.len() - 30] {
                let result = parse_pcd(&bytes[..len]);
                assert!(
                    result.is_err(),
                    "{encoding:?} truncated to {len} was accepted"
                );
            }
        }
    }

    #[test]
    fn garbage_and_hostile_headers_are_errors_not_panics() {
        let mut rng_bytes: Vec<u8> = (0..2000u32)
            .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
            .collect();
        assert!(parse_pcd(&rng_bytes).is_err());
        let valid = encode_pcd(&awkward_cloud(5, 1), PcdEncoding::Binary).unwrap();
        rng_bytes.splice(0..0, valid[..valid.len() - 40].iter().copied());
        assert!(parse_pcd(&rng_bytes[..valid.len() - 10]).is_err());
        let cases = [
            header("x y z", "4 4 4", "F F F", 1, "ascii") + "1 2\n",
            header("x y z", "4 4 4", "F F F", 1, "ascii") + "1 2 abc\n",
            header("x y z", "4 4 4", "F F F", 2, "ascii") + "1 2 3\n",
            header("x y", "4 4", "F F", 1, "ascii") + "1 2\n",
            header("x y z", "4 4 4", "I I I", 1, "ascii") + "1 2 3\n",
            header("x y z", "4 4 4", "F F F", 1, "binary_compressed") + "\x01\x00",
            header("x y z", "4 4 4", "F F F", usize::MAX / 2, "binary") + "abcdefghijkl",
            "VERSION 0.7\nFIELDS x y z _\nSIZE 4 4 4 8\nTYPE F F F U\nCOUNT 1 1 1 99999999999\n\
             WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA binary\n"
                .to_string(),
            "VERSION 0.7\nFIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n"
                .to_string(),
            "VERSION 0.7\nFIELDS x y z\n".to_string(),
        ];
        for case in &cases {
            assert!(parse_pcd(case.as_bytes()).is_err(), "accepted:\n{case}");
        }
    }
}
