//! Reading and writing a package directory.

use super::TargetPackage;
use super::manifest::{MaterialRecord, PACKAGE_FORMAT, PackageManifest};
use super::obj::{from_obj, to_obj};
use crate::error::TargetError;
use crate::target::Target;
use std::path::Path;

/// The manifest's file name in a package directory.
pub const MANIFEST_FILE: &str = "target.toml";
/// The mesh's file name in a package directory.
pub const MESH_FILE: &str = "mesh.obj";

/// True when `path` is a directory holding a [`MANIFEST_FILE`].
pub fn is_package_dir(path: &Path) -> bool {
    path.is_dir() && path.join(MANIFEST_FILE).is_file()
}

/// Writes `target` and `manifest` into `dir` (created if missing; existing
/// package files are replaced). The manifest's mesh file name must be
/// [`MESH_FILE`].
pub fn write_package(
    dir: &Path,
    target: &Target,
    manifest: &PackageManifest,
) -> Result<(), TargetError> {
    if manifest.mesh.file != MESH_FILE {
        return Err(TargetError::InvalidPackage(format!(
            "mesh.file must be {MESH_FILE}, not {}",
            manifest.mesh.file
        )));
    }
    let io = |e: std::io::Error| TargetError::Read {
        path: dir.to_owned(),
        message: e.to_string(),
    };
    std::fs::create_dir_all(dir).map_err(io)?;
    let text = toml::to_string(manifest)
        .map_err(|e| TargetError::InvalidPackage(format!("serialising the manifest: {e}")))?;
    let header = format!(
        "spacepose target package '{}': body frame, metres, origin at the centre of mass",
        manifest.name
    );
    std::fs::write(dir.join(MESH_FILE), to_obj(target.mesh(), &header)).map_err(io)?;
    std::fs::write(dir.join(MANIFEST_FILE), text).map_err(io)
}

/// Loads the package in `dir`: parses and checks the manifest, reads the
/// mesh, and assembles the target with the recorded materials, symmetry
/// group and twins.
pub fn load_package(dir: &Path) -> Result<TargetPackage, TargetError> {
    let read = |name: &str| {
        std::fs::read_to_string(dir.join(name)).map_err(|e| TargetError::Read {
            path: dir.join(name),
            message: e.to_string(),
        })
    };
    let manifest = parse_manifest(&read(MANIFEST_FILE)?).map_err(|e| in_dir(dir, e))?;
    let mesh = from_obj(&read(&manifest.mesh.file)?).map_err(|e| in_dir(dir, e))?;
    let target = target_of(mesh, &manifest).map_err(|e| in_dir(dir, e))?;
    Ok(TargetPackage {
        target,
        manifest,
        dir: Some(dir.to_owned()),
    })
}

/// Parses and checks a manifest's text (a package's `target.toml`).
pub fn parse_manifest(text: &str) -> Result<PackageManifest, TargetError> {
    let manifest: PackageManifest =
        toml::from_str(text).map_err(|e| TargetError::InvalidPackage(e.to_string()))?;
    if manifest.format != PACKAGE_FORMAT {
        return Err(TargetError::InvalidPackage(format!(
            "format {} (this spacepose reads format {PACKAGE_FORMAT}; rebuild the package \
             with `spacepose target prepare`)",
            manifest.format
        )));
    }
    manifest.calibration.validate()?;
    Ok(manifest)
}

/// The target a manifest describes, on `mesh`.
pub(crate) fn target_of(
    mesh: crate::mesh::Mesh,
    manifest: &PackageManifest,
) -> Result<Target, TargetError> {
    let materials = manifest
        .materials
        .iter()
        .map(MaterialRecord::material)
        .collect::<Result<Vec<_>, _>>()?;
    Target::new(&manifest.name, mesh, materials, manifest.symmetry.group())?
        .with_twins(manifest.symmetry.twins())
}

fn in_dir(dir: &Path, e: TargetError) -> TargetError {
    TargetError::InvalidPackage(format!("{}: {e}", dir.display()))
}
