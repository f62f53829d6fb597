//! Versioned binary map files, so a service starts without rebuilding.
//!
//! Layout (little endian):
//! `b"SPNDTMAP"` | version `u32` | payload length `u64` | FNV-1a-64 of the
//! payload `u64` | payload (postcard encoding of [`MapFileV1`]).
//! The kd-tree over the means is rebuilt on load (milliseconds); the lookup
//! grid is stored.

use super::{LookupGrid, NdtMap};
use crate::error::RegistrationError;
use crate::kdtree::build_tree;
use crate::params::NdtMapParams;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// First bytes of every map file.
pub const MAP_MAGIC: &[u8; 8] = b"SPNDTMAP";
/// The format version this build writes and reads.
pub const MAP_FORMAT_VERSION: u32 = 1;
const HEADER_LEN: usize = 8 + 4 + 8 + 8;

#[derive(Serialize, Deserialize)]
struct MapFileV1 {
    params: NdtMapParams,
    model_points: u64,
    means: Vec<[f64; 3]>,
    covariances: Vec<[f64; 6]>,
    inv_covariances: Vec<[f64; 6]>,
    counts: Vec<u32>,
    grid: LookupGrid,
}

/// FNV-1a, 64 bit: a cheap guard against truncation and bit rot.
fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

fn sym_to_array(m: &Matrix3<f64>) -> [f64; 6] {
    [
        m[(0, 0)],
        m[(0, 1)],
        m[(0, 2)],
        m[(1, 1)],
        m[(1, 2)],
        m[(2, 2)],
    ]
}

fn array_to_sym(a: &[f64; 6]) -> Matrix3<f64> {
    Matrix3::new(a[0], a[1], a[2], a[1], a[3], a[4], a[2], a[4], a[5])
}

impl NdtMap {
    /// Encodes the map (header + payload) into bytes.
    pub fn to_bytes(&self) -> Result<Vec<u8>, RegistrationError> {
        let body = MapFileV1 {
            params: self.params,
            model_points: self.model_points as u64,
            means: self.means.iter().map(|m| [m.x, m.y, m.z]).collect(),
            covariances: self.covariances.iter().map(sym_to_array).collect(),
            inv_covariances: self.inv_covariances.iter().map(sym_to_array).collect(),
            counts: self.counts.clone(),
            grid: self.grid.clone(),
        };
        let payload = postcard::to_stdvec(&body).map_err(|e| RegistrationError::MapCorrupt {
            path: Default::default(),
            reason: format!("encoding: {e}"),
        })?;
        let mut out = Vec::with_capacity(HEADER_LEN + payload.len());
        out.extend_from_slice(MAP_MAGIC);
        out.extend_from_slice(&MAP_FORMAT_VERSION.to_le_bytes());
        out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        out.extend_from_slice(&fnv1a64(&payload).to_le_bytes());
        out.extend_from_slice(&payload);
        Ok(out)
    }

    /// Writes the map to `path` (see the module docs for the format).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), RegistrationError> {
        let path = path.as_ref();
        let bytes = self.to_bytes()?;
        std::fs::write(path, bytes).map_err(|source| RegistrationError::MapIo {
            path: path.to_path_buf(),
            source,
        })
    }

    /// Reads a map written by [`NdtMap::save`]. A file with another magic,
    /// another format version, a bad checksum or inconsistent content is an
    /// error.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, RegistrationError> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| RegistrationError::MapIo {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_bytes_at(&bytes, path)
    }

    /// Decodes a map from bytes produced by [`NdtMap::to_bytes`].
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, RegistrationError> {
        Self::from_bytes_at(bytes, Path::new("<memory>"))
    }

    fn from_bytes_at(bytes: &[u8], path: &Path) -> Result<Self, RegistrationError> {
        let corrupt = |reason: String| RegistrationError::MapCorrupt {
            path: path.to_path_buf(),
            reason,
        };
        if bytes.len() < 8 || &bytes[..8] != MAP_MAGIC {
            return Err(RegistrationError::MapBadMagic {
                path: path.to_path_buf(),
            });
        }
        if bytes.len() < HEADER_LEN {
            return Err(corrupt("truncated header".into()));
        }
        let u32_at =
            |o: usize| u32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
        let u64_at = |o: usize| u64::from(u32_at(o)) | (u64::from(u32_at(o + 4)) << 32);
        let version = u32_at(8);
        if version != MAP_FORMAT_VERSION {
            return Err(RegistrationError::MapVersion {
                path: path.to_path_buf(),
                found: version,
                expected: MAP_FORMAT_VERSION,
            });
        }
        let payload = &bytes[HEADER_LEN..];
        if u64_at(12) != payload.len() as u64 {
            return Err(corrupt(format!(
                "payload is {} bytes, header says {}",
                payload.len(),
                u64_at(12)
            )));
        }
        if u64_at(20) != fnv1a64(payload) {
            return Err(corrupt("checksum mismatch".into()));
        }
        let body: MapFileV1 =
            postcard::from_bytes(payload).map_err(|e| corrupt(format!("decoding: {e}")))?;
        Self::from_body(body).map_err(corrupt)
    }

    fn from_body(body: MapFileV1) -> Result<Self, String> {
        let n = body.means.len();
        body.params.validate().map_err(|e| e.to_string())?;
        if n == 0
            || body.covariances.len() != n
            || body.inv_covariances.len() != n
            || body.counts.len() != n
        {
            return Err("inconsistent cell arrays".into());
        }
        let finite = |a: &[f64]| a.iter().all(|v| v.is_finite());
        if !body.means.iter().all(|m| finite(m))
            || !body.covariances.iter().all(|c| finite(c))
            || !body.inv_covariances.iter().all(|c| finite(c))
        {
            return Err("non-finite cell".into());
        }
        body.grid.check(n)?;
        let means: Vec<Vector3<f64>> = body.means.iter().map(|m| Vector3::from(*m)).collect();
        let mut grid = body.grid;
        grid.pack(&means);
        let tree = build_tree(&means).map_err(|e| e.to_string())?;
        let covariances: Vec<_> = body.covariances.iter().map(array_to_sym).collect();
        Ok(Self {
            params: body.params,
            model_points: body.model_points as usize,
            means,
            normals: super::normals_of(&covariances),
            covariances,
            inv_covariances: body.inv_covariances.iter().map(array_to_sym).collect(),
            counts: body.counts,
            grid,
            tree,
        })
    }
}
