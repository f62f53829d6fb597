//! Point-cloud files: PCD (`.pcd`) and PLY (`.ply`) holding [`Point`]s.
//!
//! Files are written with the fields `x y z t intensity`: positions and
//! intensity as 32-bit floats, the timestamp `t` as a 64-bit float, so a
//! write/read round trip is bit-exact in every encoding (ASCII numbers are
//! printed with Rust's shortest round-trip formatting).
//!
//! Two readers:
//! - [`read_cloud`], the plain reader for files spacepose writes itself: the
//!   time is the `t` field (`float` or `double`, absolute seconds) and reads
//!   as 0 when missing.
//! - [`read_cloud_timed`], for **recorded input** from other tools: the time
//!   field is chosen by a [`TimeMapping`] (`t`, `time`, `timestamp`, Livox
//!   `offset_time`, or a configured name; any numeric type; unit and base
//!   configurable), and the result says which field was used, or that there
//!   was none so the caller derives times ([`time`] module).
//!
//! Both are tolerant of what other tools produce: `intensity` may be missing
//! (it reads as 0), `x y z` may be `float` or `double`, `intensity` may be any
//! numeric type, and unknown fields are skipped. Corrupt or truncated files give
//! [`GeometryError::Malformed`], never a panic. Whole files are read into
//! memory first (lidar frames are a few MB).

mod fields;
pub mod pcd;
pub mod ply;
pub mod time;

use std::path::Path;

use crate::error::GeometryError;
use crate::point::Point;

pub use pcd::{PcdEncoding, read_pcd, write_pcd};
pub use ply::{PlyEncoding, read_ply, write_ply};
pub use time::{PointTimes, TimeBase, TimeField, TimeMapping, TimeUnit, TimedCloud};

/// A file format and encoding to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CloudFormat {
    /// PCD v0.7, `DATA ascii`.
    PcdAscii,
    /// PCD v0.7, `DATA binary` (little-endian records).
    PcdBinary,
    /// PLY 1.0, `format ascii`.
    PlyAscii,
    /// PLY 1.0, `format binary_little_endian`.
    PlyBinary,
}

impl CloudFormat {
    /// The file extension of this format, without the dot (`"pcd"` or `"ply"`).
    pub fn extension(self) -> &'static str {
        match self {
            Self::PcdAscii | Self::PcdBinary => "pcd",
            Self::PlyAscii | Self::PlyBinary => "ply",
        }
    }
}

/// Reads a cloud, choosing the reader by extension (`.pcd` or `.ply`, any
/// case); the encoding is taken from the file header.
///
/// # Errors
/// [`GeometryError::BadExtension`] for other extensions, otherwise as
/// [`read_pcd`] / [`read_ply`].
pub fn read_cloud(path: impl AsRef<Path>) -> Result<Vec<Point>, GeometryError> {
    let path = path.as_ref();
    match lowercase_extension(path).as_deref() {
        Some("pcd") => read_pcd(path),
        Some("ply") => read_ply(path),
        _ => Err(bad_extension(path, "expected a .pcd or .ply extension")),
    }
}

/// Reads a recorded cloud (`.pcd` or `.ply`) with its per-point time field
/// chosen by `mapping`. Field times are converted to seconds (relative ones
/// stay relative: see [`TimedCloud::into_absolute`]); without a time field
/// every `t` is NaN and [`TimedCloud::time`] is `None`. PLY files recognise
/// only the names of [`time::TIME_FIELD_NAMES`].
///
/// # Errors
/// As [`read_cloud`], plus [`GeometryError::Unsupported`] when a configured
/// time field is absent or has more than one value per point.
pub fn read_cloud_timed(
    path: impl AsRef<Path>,
    mapping: &TimeMapping,
) -> Result<TimedCloud, GeometryError> {
    let path = path.as_ref();
    let mut cloud = match lowercase_extension(path).as_deref() {
        Some("pcd") => pcd::read_pcd_timed(path, mapping)?,
        Some("ply") => ply::read_ply_timed(path, mapping)?,
        _ => return Err(bad_extension(path, "expected a .pcd or .ply extension")),
    };
    let scale = cloud.time.as_ref().map(|f| f.unit.seconds_per_unit());
    for p in &mut cloud.points {
        p.t = scale.map_or(f64::NAN, |s| p.t * s);
    }
    Ok(cloud)
}

/// Writes a cloud in `format`; the extension of `path` must match the format
/// family (`.pcd` for PCD, `.ply` for PLY) so files are never mislabelled.
///
/// # Errors
/// [`GeometryError::BadExtension`] on a mismatch, [`GeometryError::Io`] if the
/// file cannot be written.
pub fn write_cloud(
    path: impl AsRef<Path>,
    points: &[Point],
    format: CloudFormat,
) -> Result<(), GeometryError> {
    let path = path.as_ref();
    if lowercase_extension(path).as_deref() != Some(format.extension()) {
        let message = format!(
            "{format:?} must be written to a .{} file",
            format.extension()
        );
        return Err(bad_extension(path, &message));
    }
    match format {
        CloudFormat::PcdAscii => write_pcd(path, points, PcdEncoding::Ascii),
        CloudFormat::PcdBinary => write_pcd(path, points, PcdEncoding::Binary),
        CloudFormat::PlyAscii => write_ply(path, points, PlyEncoding::Ascii),
        CloudFormat::PlyBinary => write_ply(path, points, PlyEncoding::BinaryLittleEndian),
    }
}

fn bad_extension(path: &Path, message: &str) -> GeometryError {
    GeometryError::BadExtension {
        path: path.to_path_buf(),
        message: message.to_owned(),
    }
}

fn lowercase_extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
}

#[cfg(test)]
pub(crate) mod test_support {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Points with awkward values: full-precision f32 positions, absolute
    /// clock timestamps with sub-ns parts, tiny and negative numbers.
    pub(crate) fn awkward_cloud(n: usize, seed: u64) -> Vec<Point> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut points: Vec<Point> = (0..n)
            .map(|_| {
                Point::new(
                    rng.random_range(-20.0f32..20.0),
                    rng.random_range(-20.0f32..20.0),
                    rng.random_range(0.1f32..80.0),
                    rng.random_range(0.0f32..4096.0),
                    1.7e9 + rng.random_range(0.0..1.0),
                )
            })
            .collect();
        points.push(Point::new(-0.0, 1e-38, -3.4e38, 1e-45, 1.0 / 3.0));
        points.push(Point::new(f32::MIN_POSITIVE, 0.1, 123456.79, 0.0, -1e-300));
        points
    }

    /// Bit-level equality of two clouds (distinguishes -0.0 and NaN payloads).
    pub(crate) fn assert_bit_equal(a: &[Point], b: &[Point]) {
        assert_eq!(a.len(), b.len());
        for (i, (p, q)) in a.iter().zip(b).enumerate() {
            let bits = |p: &Point| {
                (
                    p.x.to_bits(),
                    p.y.to_bits(),
                    p.z.to_bits(),
                    p.intensity.to_bits(),
                    p.t.to_bits(),
                )
            };
            assert_eq!(bits(p), bits(q), "point {i}: {p:?} vs {q:?}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::test_support::*;
    use super::*;

    #[test]
    fn dispatch_by_extension_round_trips_every_format() {
        let dir = tempfile::tempdir().unwrap();
        let points = awkward_cloud(50, 5);
        for (name, format) in [
            ("a.pcd", CloudFormat::PcdAscii),
            ("b.PCD", CloudFormat::PcdBinary),
            ("c.ply", CloudFormat::PlyAscii),
            ("d.ply", CloudFormat::PlyBinary),
        ] {
            let path = dir.path().join(name);
            write_cloud(&path, &points, format).unwrap();
            assert_bit_equal(&read_cloud(&path).unwrap(), &points);
        }
    }

    #[test]
    fn extensions_are_checked_and_paths_reported() {
        let dir = tempfile::tempdir().unwrap();
        let points = awkward_cloud(3, 1);
        let wrong = dir.path().join("cloud.ply");
        assert!(matches!(
            write_cloud(&wrong, &points, CloudFormat::PcdBinary),
            Err(GeometryError::BadExtension { .. })
        ));
        assert!(matches!(
            read_cloud(dir.path().join("cloud.xyz")),
            Err(GeometryError::BadExtension { .. })
        ));
        let missing = dir.path().join("missing.pcd");
        match read_cloud(&missing) {
            Err(GeometryError::Io { path, .. }) => assert_eq!(path, missing),
            other => panic!("expected an I/O error, got {other:?}"),
        }
    }
}
