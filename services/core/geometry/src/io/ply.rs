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

use super::fields::{Issue, Role, io_error};
use super::time::{TIME_FIELD_NAMES, TimeMapping, TimedCloud};
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

/// Reads a PLY file with the time field chosen by `mapping` among
/// [`TIME_FIELD_NAMES`] (raw values in `t`; see [`super::read_cloud_timed`]).
pub(crate) fn read_ply_timed(
    path: &Path,
    mapping: &TimeMapping,
) -> Result<TimedCloud, GeometryError> {
    let bytes = std::fs::read(path).map_err(io_error(path))?;
    parse_ply_timed(&bytes, mapping).map_err(|issue| issue.at(path, FORMAT))
}

/// A [`Point`] as seen by `ply-rs-bw`, with the values of every recognised
/// time property (the parser cannot be told which one is wanted).
#[derive(Debug, Clone, Copy)]
struct PlyPoint {
    point: Point,
    /// Values of the [`TIME_FIELD_NAMES`] properties, in that order.
    times: [f64; 4],
}

impl PlyPoint {
    fn of(point: Point) -> Self {
        PlyPoint {
            point,
            times: [0.0; 4],
        }
    }

    fn set(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        if let Some(k) = TIME_FIELD_NAMES.iter().position(|n| *n == name) {
            self.times[k] = value;
        }
        match Role::of(name, "t") {
            Some(role) => role.set(&mut self.point, value),
            None if TIME_FIELD_NAMES.contains(&name) => {}
            None => return PropertyAccessResult::Ignored,
        }
        PropertyAccessResult::Set
    }

    /// Integers are accepted for intensity and time only (positions in
    /// integer units would need a scale we do not know); the plain reader
    /// refuses integer `t` from the header.
    fn set_integer(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        match Role::of(name, "t") {
            Some(Role::X | Role::Y | Role::Z) => PropertyAccessResult::UnsupportedType,
            _ => self.set(name, value),
        }
    }
}

impl PropertyAccess for PlyPoint {
    fn new() -> Self {
        Self::of(Point::default())
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
        match Role::of(name, "t")? {
            Role::X => Some(self.point.x),
            Role::Y => Some(self.point.y),
            Role::Z => Some(self.point.z),
            Role::Intensity => Some(self.point.intensity),
            Role::T => None,
        }
    }
    fn get_double(&self, name: &str) -> Option<f64> {
        (Role::of(name, "t")? == Role::T).then_some(self.point.t)
    }
}

/// The plain reader: time in `t`, a float.
fn parse_ply(bytes: &[u8]) -> Result<Vec<Point>, Issue> {
    let (points, _) = decode_ply(bytes, |_| Ok(Some("t".to_owned())), false)?;
    Ok(points.into_iter().map(|p| p.point).collect())
}

fn parse_ply_timed(bytes: &[u8], mapping: &TimeMapping) -> Result<TimedCloud, Issue> {
    let mut time = None;
    let (points, _) = decode_ply(
        bytes,
        |vertex| {
            let fields = vertex.properties.iter().map(|(name, def)| {
                let float = matches!(
                    def.data_type,
                    PropertyType::Scalar(ScalarType::Float | ScalarType::Double)
                );
                (name.as_str(), !float)
            });
            time = mapping.resolve(fields).map_err(Issue::Unsupported)?;
            Ok(time.as_ref().map(|f| f.name.clone()))
        },
        true,
    )?;
    let slot = match &time {
        Some(f) => Some(
            TIME_FIELD_NAMES
                .iter()
                .position(|n| *n == f.name)
                .ok_or_else(|| {
                    Issue::Unsupported(format!(
                        "PLY time field must be one of {TIME_FIELD_NAMES:?}"
                    ))
                })?,
        ),
        None => None,
    };
    let points = points
        .into_iter()
        .map(|p| Point {
            t: slot.map_or(f64::NAN, |k| p.times[k]),
            ..p.point
        })
        .collect();
    Ok(TimedCloud { points, time })
}

/// Parses the header, lets `choose_time` pick the time property, checks the
/// vertex properties and reads the payload.
fn decode_ply(
    bytes: &[u8],
    choose_time: impl FnOnce(&ElementDef) -> Result<Option<String>, Issue>,
    any_numeric_time: bool,
) -> Result<(Vec<PlyPoint>, Option<String>), Issue> {
    let parser = Parser::<PlyPoint>::new();
    let mut reader = Reader::new(bytes);
    let header = parser.read_header(&mut reader).map_err(malformed)?;
    let vertex = header
        .elements
        .get(VERTEX)
        .ok_or_else(|| Issue::Malformed("no vertex element".into()))?;
    let time_name = choose_time(vertex)?;
    check_vertex_properties(vertex, time_name.as_deref().unwrap_or(""), any_numeric_time)?;
    let mut payload = parser
        .read_payload(&mut reader, &header)
        .map_err(malformed)?;
    Ok((payload.swap_remove(VERTEX).unwrap_or_default(), time_name))
}

fn check_vertex_properties(
    vertex: &ElementDef,
    time_name: &str,
    any_numeric_time: bool,
) -> Result<(), Issue> {
    for name in ["x", "y", "z"] {
        if !vertex.properties.contains_key(name) {
            return Err(Issue::Malformed(format!("vertex has no {name} property")));
        }
    }
    for (name, def) in &vertex.properties {
        let Some(role) = Role::of(name, time_name) else {
            continue;
        };
        let integer_ok = role == Role::Intensity || (role == Role::T && any_numeric_time);
        match def.data_type {
            PropertyType::Scalar(ScalarType::Float | ScalarType::Double) => {}
            PropertyType::Scalar(_) if integer_ok => {}
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
        points.iter().copied().map(PlyPoint::of).collect(),
    );
    let mut out = Vec::with_capacity(256 + points.len() * 28);
    Writer::new().write_ply(&mut out, &mut ply)?;
    Ok(out)
}

fn malformed(e: impl std::fmt::Display) -> Issue {
    Issue::Malformed(e.to_string())
}

#[cfg(test)]
#[path = "ply_tests.rs"]
mod tests;
