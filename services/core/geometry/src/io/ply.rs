//! PLY 1.0 files of [`Point`]s (the `vertex` element).
//!
//! Built on `ply-rs-bw` 4.0: its parser and writer are generic over a
//! `PropertyAccess` element type, so [`PlyPoint`] maps the `x y z t
//! intensity` properties straight into a [`Point`] (no per-point map or
//! allocation) and ignores every other property and element (faces, colours,
//! normals). The parser reports truncated or corrupt payloads as errors and
//! caps its pre-allocations, so hostile headers cannot exhaust memory.
//!
//! Limitations inherited from `ply-rs-bw`: ASCII numbers must look like
//! `-1.5`, `2`, or `3.0e-7` (no `.5`, `5.`, `nan` or `inf`), so non-finite
//! values can only be stored in binary PLY; writing them as ASCII is refused
//! with [`GeometryError::Unsupported`] rather than producing an unreadable file.

use std::path::Path;

use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    Addable, ElementDef, Encoding, Ply, PropertyAccess, PropertyAccessResult, PropertyDef,
    PropertyType, ScalarType,
};
use ply_rs_bw::writer::Writer;

use super::{Issue, Role, io_error};
use crate::error::GeometryError;
use crate::point::Point;

const FORMAT: &str = "PLY";
const VERTEX: &str = "vertex";

/// The payload encoding to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlyEncoding {
    /// `format ascii 1.0`; finite values only.
    Ascii,
    /// `format binary_little_endian 1.0`.
    BinaryLittleEndian,
}

/// Reads the `vertex` element of a PLY file (ascii, binary little- or
/// big-endian).
///
/// # Errors
/// [`GeometryError::Io`] if the file cannot be read,
/// [`GeometryError::Malformed`] for corrupt or truncated content or a missing
/// `vertex` element / `x y z` property, [`GeometryError::Unsupported`] for
/// integer or list coordinates.
pub fn read_ply(path: impl AsRef<Path>) -> Result<Vec<Point>, GeometryError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(io_error(path))?;
    parse_ply(&bytes).map_err(|issue| issue.at(path, FORMAT))
}

/// Writes `points` as one `vertex` element with properties
/// `float x, float y, float z, double t, float intensity`.
///
/// # Errors
/// [`GeometryError::Unsupported`] for a non-finite value in ASCII,
/// [`GeometryError::Io`] if the file cannot be written.
pub fn write_ply(
    path: impl AsRef<Path>,
    points: &[Point],
    encoding: PlyEncoding,
) -> Result<(), GeometryError> {
    let path = path.as_ref();
    if encoding == PlyEncoding::Ascii
        && let Some(i) = points.iter().position(|p| !p.is_finite())
    {
        let message = format!("ASCII PLY cannot hold the non-finite point {i}; use binary");
        return Err(Issue::Unsupported(message).at(path, FORMAT));
    }
    let bytes = encode_ply(points, encoding).map_err(io_error(path))?;
    std::fs::write(path, bytes).map_err(io_error(path))
}

/// A [`Point`] as seen by `ply-rs-bw`.
#[derive(Debug, Clone, Copy, Default)]
struct PlyPoint(Point);

impl PlyPoint {
    fn set(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        match Role::of(name) {
            Some(role) => {
                role.set(&mut self.0, value);
                PropertyAccessResult::Set
            }
            None => PropertyAccessResult::Ignored,
        }
    }

    /// Integers are accepted for intensity only (positions and time in
    /// integer units would need a scale we do not know).
    fn set_integer(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        match Role::of(name) {
            Some(Role::Intensity) => self.set(name, value),
            Some(_) => PropertyAccessResult::UnsupportedType,
            None => PropertyAccessResult::Ignored,
        }
    }
}

impl PropertyAccess for PlyPoint {
    fn new() -> Self {
        Self::default()
    }
    fn set_float(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        self.set(name, value as f64)
    }
    fn set_double(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        self.set(name, value)
    }
    fn set_char(&mut self, name: &str, value: i8) -> PropertyAccessResult {
        self.set_integer(name, value as f64)
    }
    fn set_uchar(&mut self, name: &str, value: u8) -> PropertyAccessResult {
        self.set_integer(name, value as f64)
    }
    fn set_short(&mut self, name: &str, value: i16) -> PropertyAccessResult {
        self.set_integer(name, value as f64)
    }
    fn set_ushort(&mut self, name: &str, value: u16) -> PropertyAccessResult {
        self.set_integer(name, value as f64)
    }
    fn set_int(&mut self, name: &str, value: i32) -> PropertyAccessResult {
        self.set_integer(name, value as f64)
    }
    fn set_uint(&mut self, name: &str, value: u32) -> PropertyAccessResult {
        self.set_integer(name, value as f64)
    }
    fn get_float(&self, name: &str) -> Option<f32> {
        match Role::of(name)? {
            Role::X => Some(self.0.x),
            Role::Y => Some(self.0.y),
            Role::Z => Some(self.0.z),
            Role::Intensity => Some(self.0.intensity),
            Role::T => None,
        }
    }
    fn get_double(&self, name: &str) -> Option<f64> {
        (Role::of(name)? == Role::T).then_some(self.0.t)
    }
}

fn parse_ply(bytes: &[u8]) -> Result<Vec<Point>, Issue> {
    let parser = Parser::<PlyPoint>::new();
    let mut reader = Reader::new(bytes);
    let header = parser.read_header(&mut reader).map_err(malformed)?;
    let vertex = header
        .elements
        .get(VERTEX)
        .ok_or_else(|| Issue::Malformed("no vertex element".into()))?;
    check_vertex_properties(vertex)?;
    let mut payload = parser
        .read_payload(&mut reader, &header)
        .map_err(malformed)?;
    let points = payload.swap_remove(VERTEX).unwrap_or_default();
    Ok(points.into_iter().map(|p| p.0).collect())
}

fn check_vertex_properties(vertex: &ElementDef) -> Result<(), Issue> {
    for name in ["x", "y", "z"] {
        if !vertex.properties.contains_key(name) {
            return Err(Issue::Malformed(format!("vertex has no {name} property")));
        }
    }
    for (name, def) in &vertex.properties {
        let Some(role) = Role::of(name) else { continue };
        match def.data_type {
            PropertyType::Scalar(ScalarType::Float | ScalarType::Double) => {}
            PropertyType::Scalar(_) if role == Role::Intensity => {}
            ref other => {
                return Err(Issue::Unsupported(format!(
                    "vertex property {name} is {other:?}"
                )));
            }
        }
    }
    Ok(())
}

fn encode_ply(points: &[Point], encoding: PlyEncoding) -> std::io::Result<Vec<u8>> {
    let mut vertex = ElementDef::new(VERTEX.to_owned());
    vertex.count = points.len();
    for (name, scalar) in [
        ("x", ScalarType::Float),
        ("y", ScalarType::Float),
        ("z", ScalarType::Float),
        ("t", ScalarType::Double),
        ("intensity", ScalarType::Float),
    ] {
        vertex.properties.add(PropertyDef::new(
            name.to_owned(),
            PropertyType::Scalar(scalar),
        ));
    }
    let mut ply = Ply::<PlyPoint>::new();
    ply.header.encoding = match encoding {
        PlyEncoding::Ascii => Encoding::Ascii,
        PlyEncoding::BinaryLittleEndian => Encoding::BinaryLittleEndian,
    };
    ply.header.elements.add(vertex);
    ply.payload.insert(
        VERTEX.to_owned(),
        points.iter().copied().map(PlyPoint).collect(),
    );
    let mut out = Vec::with_capacity(256 + points.len() * 28);
    Writer::new().write_ply(&mut out, &mut ply)?;
    Ok(out)
}

fn malformed(e: impl std::fmt::Display) -> Issue {
    Issue::Malformed(e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_support::*;

    fn finite_cloud() -> Vec<Point> {
        awkward_cloud(300, 4)
    }

    #[test]
    fn ascii_and_binary_round_trip_bit_exactly() {
        let points = finite_cloud();
        for encoding in [PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian] {
            let bytes = encode_ply(&points, encoding).unwrap();
            assert_bit_equal(&parse_ply(&bytes).unwrap(), &points);
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cloud.ply");
        write_ply(&path, &points, PlyEncoding::Ascii).unwrap();
        assert_bit_equal(&read_ply(&path).unwrap(), &points);
    }

    #[test]
    fn non_finite_values_need_binary() {
        let points = [Point::new(f32::NAN, 1.0, 2.0, 0.0, f64::INFINITY)];
        let back =
            parse_ply(&encode_ply(&points, PlyEncoding::BinaryLittleEndian).unwrap()).unwrap();
        assert!(back[0].x.is_nan() && back[0].t == f64::INFINITY);
        let dir = tempfile::tempdir().unwrap();
        assert!(matches!(
            write_ply(dir.path().join("a.ply"), &points, PlyEncoding::Ascii),
            Err(GeometryError::Unsupported { .. })
        ));
        assert!(
            parse_ply(&encode_ply(&[], PlyEncoding::Ascii).unwrap())
                .unwrap()
                .is_empty()
        );
    }

    #[test]
    fn missing_optional_fields_default_to_zero_and_extras_are_ignored() {
        let text = "ply\nformat ascii 1.0\ncomment from another tool\nelement vertex 2\n\
                    property double x\nproperty double y\nproperty double z\n\
                    property uchar red\nproperty float nx\nelement face 1\n\
                    property list uchar int vertex_indices\nend_header\n\
                    1.5 -2 3e2 255 0.5\n0 0 1 0 1\n3 0 1 1\n";
        let points = parse_ply(text.as_bytes()).unwrap();
        assert_eq!(
            points,
            [
                Point::new(1.5, -2.0, 300.0, 0.0, 0.0),
                Point::new(0.0, 0.0, 1.0, 0.0, 0.0)
            ]
        );
    }

    #[test]
    fn float_time_and_integer_intensity_are_read() {
        let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 1\n\
                          property ushort intensity\nproperty float t\nproperty float x\n\
                          property float y\nproperty float z\nend_header\n"
            .to_vec();
        bytes.extend_from_slice(&4000u16.to_le_bytes());
        for v in [0.25f32, 1.0, 2.0, 3.0] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        assert_eq!(
            parse_ply(&bytes).unwrap(),
            [Point::new(1.0, 2.0, 3.0, 4000.0, 0.25)]
        );
    }

    #[test]
    fn truncated_files_are_errors() {
        let points = awkward_cloud(20, 3);
        for encoding in [PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian] {
            let bytes = encode_ply(&points, encoding).unwrap();
            for len in [0, 10, 60, bytes.len() / 2, bytes.len() - 30] {
                assert!(
                    parse_ply(&bytes[..len]).is_err(),
                    "{encoding:?} truncated to {len} accepted"
                );
            }
        }
    }

    #[test]
    fn garbage_and_hostile_headers_are_errors_not_panics() {
        let garbage: Vec<u8> = (0..2000u32)
            .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
            .collect();
        assert!(parse_ply(&garbage).is_err());
        let cases: [&[u8]; 7] = [
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n",
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty int x\nproperty int y\nproperty int z\nend_header\n1 2 3\n",
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 zz\n",
            b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n",
            b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n\x00\x00",
            b"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty list uint float x\nproperty float y\nproperty float z\nend_header\n\xff\xff\xff\xff",
            b"ply\nformat ascii 1.0\nelement face 1\nproperty float x\nend_header\n1\n",
        ];
        for case in cases {
            assert!(
                parse_ply(case).is_err(),
                "accepted:\n{}",
                String::from_utf8_lossy(case)
            );
        }
    }
}
