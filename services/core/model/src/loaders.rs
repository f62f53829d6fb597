//! Mesh files: STL (stl_io), OBJ (tobj), PLY (ply-rs-bw).
//!
//! Frame convention of loaded targets: coordinates are read in the file's own units and
//! multiplied by `scale`, the result being in metres; the axes are the file's axes; the
//! origin is moved to the area-weighted centroid of the surface, which is the centre of mass
//! if the target is a uniform thin shell (the only assumption possible without mass data).
//! The whole mesh gets [`Material::default_structure`] (structure class, ρ = 0.6, the mean of
//! seed 002 §3.1, seed 004 Table I structure ranges) and the identity as only symmetry.
//!
//! Polygons (OBJ, PLY) are split into triangle fans. OBJ materials (`mtllib`) are ignored;
//! points and lines are skipped.
//!
//! [`Material::default_structure`]: crate::material::Material::default_structure

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use nalgebra::{Rotation3, Vector3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

use crate::error::TargetError;
use crate::mesh::Mesh;

/// Raw vertices (file units) and triangles.
type RawMesh = (Vec<Vector3<f64>>, Vec<[u32; 3]>);

/// Reads `path` (extension decides the format), applies `scale` and recentres on the
/// area-weighted centroid. Returns the mesh with its name (the file stem); `Target::load`
/// wraps it in a target.
pub(crate) fn load_mesh(path: &Path, scale: f64) -> Result<(String, Mesh), TargetError> {
    load_mesh_with_origin(path, scale).map(|(name, mesh, _)| (name, mesh))
}

/// [`load_mesh`], also returning where the body origin (the centroid) lies
/// in the scaled file frame (m).
pub(crate) fn load_mesh_with_origin(
    path: &Path,
    scale: f64,
) -> Result<(String, Mesh, Vector3<f64>), TargetError> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(TargetError::InvalidScale {
            spec: path.display().to_string(),
            scale,
        });
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let (vertices, triangles) = match ext.as_deref() {
        Some("stl") => read_stl(path)?,
        Some("obj") => read_obj(path)?,
        Some("ply") => read_ply(path)?,
        _ => {
            return Err(TargetError::UnknownExtension {
                path: path.to_owned(),
            });
        }
    };
    let invalid = |e: TargetError| TargetError::InvalidFile {
        path: path.to_owned(),
        message: match e {
            TargetError::InvalidMesh(m) => m,
            other => other.to_string(),
        },
    };
    let vertices = vertices.into_iter().map(|v| v * scale).collect();
    let materials = vec![0; triangles.len()];
    let mesh = Mesh::new(vertices, triangles, materials).map_err(invalid)?;
    let centroid = mesh.area_weighted_centroid();
    let mesh = mesh
        .transformed(&Rotation3::identity(), &-centroid)
        .map_err(invalid)?;
    let name = path
        .file_stem()
        .map_or_else(|| "mesh".to_owned(), |s| s.to_string_lossy().into_owned());
    Ok((name, mesh, centroid))
}

fn read_error(path: &Path, message: impl std::fmt::Display) -> TargetError {
    TargetError::Read {
        path: path.to_owned(),
        message: message.to_string(),
    }
}

fn open(path: &Path) -> Result<File, TargetError> {
    File::open(path).map_err(|e| read_error(path, e))
}

fn read_stl(path: &Path) -> Result<RawMesh, TargetError> {
    let mut reader = BufReader::new(open(path)?);
    let stl = stl_io::read_stl(&mut reader).map_err(|e| read_error(path, e))?;
    let vertices = stl
        .vertices
        .iter()
        .map(|v| Vector3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2])))
        .collect();
    let triangles = stl
        .faces
        .iter()
        .map(|f| {
            let mut t = [0u32; 3];
            for (dst, &src) in t.iter_mut().zip(&f.vertices) {
                *dst = u32::try_from(src).map_err(|_| read_error(path, "too many vertices"))?;
            }
            Ok(t)
        })
        .collect::<Result<_, TargetError>>()?;
    Ok((vertices, triangles))
}

fn read_obj(path: &Path) -> Result<RawMesh, TargetError> {
    // `..Default::default()` covers the fields that tobj's optional features add.
    #[allow(clippy::needless_update)]
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let (models, _materials) = tobj::load_obj(path, &options).map_err(|e| read_error(path, e))?;
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for model in &models {
        let offset =
            u32::try_from(vertices.len()).map_err(|_| read_error(path, "too many vertices"))?;
        vertices.extend(
            model
                .mesh
                .positions
                .chunks_exact(3)
                .map(|p| Vector3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))),
        );
        triangles.extend(
            model
                .mesh
                .indices
                .chunks_exact(3)
                .map(|t| [t[0] + offset, t[1] + offset, t[2] + offset]),
        );
    }
    Ok((vertices, triangles))
}

fn read_ply(path: &Path) -> Result<RawMesh, TargetError> {
    let mut file = open(path)?;
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut file)
        .map_err(|e| read_error(path, e))?;
    let vertex_elements = ply
        .payload
        .get("vertex")
        .ok_or_else(|| read_error(path, "no 'vertex' element"))?;
    let vertices = vertex_elements
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let coord = |key: &str| {
                e.get(key).and_then(scalar_f64).ok_or_else(|| {
                    read_error(path, format!("vertex {i} has no numeric '{key}' property"))
                })
            };
            Ok(Vector3::new(coord("x")?, coord("y")?, coord("z")?))
        })
        .collect::<Result<Vec<_>, TargetError>>()?;
    let faces = ply
        .payload
        .get("face")
        .ok_or_else(|| read_error(path, "no 'face' element"))?;
    let mut triangles = Vec::with_capacity(faces.len());
    for (i, face) in faces.iter().enumerate() {
        let indices = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
            .and_then(Property::to_u32_list)
            .ok_or_else(|| {
                read_error(
                    path,
                    format!("face {i} has no integer 'vertex_indices' list"),
                )
            })?;
        if indices.len() < 3 {
            return Err(read_error(
                path,
                format!("face {i} has {} vertices", indices.len()),
            ));
        }
        triangles.extend((1..indices.len() - 1).map(|k| [indices[0], indices[k], indices[k + 1]]));
    }
    Ok((vertices, triangles))
}

/// A numeric scalar PLY property as `f64` (exact for every PLY scalar type).
fn scalar_f64(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => f64::from(v),
        Property::UChar(v) => f64::from(v),
        Property::Short(v) => f64::from(v),
        Property::UShort(v) => f64::from(v),
        Property::Int(v) => f64::from(v),
        Property::UInt(v) => f64::from(v),
        Property::Float(v) => f64::from(v),
        Property::Double(v) => v,
        _ => return None,
    })
}

#[cfg(test)]
#[path = "loaders_tests.rs"]
mod tests;
