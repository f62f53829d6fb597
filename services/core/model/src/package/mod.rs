//! Target packages: a directory that holds one target spacecraft as every
//! service and command needs it, so that a user's own mesh is used exactly
//! like a built-in target.
//!
//! A package directory holds:
//! - `target.toml`, the [`PackageManifest`]: the mesh's conventions, the
//!   derived geometry, the symmetry group and twins, the per-target
//!   [`Calibration`] and how the package was made ([`Provenance`]);
//! - `mesh.obj`, the mesh in the body frame, in metres, with its origin at
//!   the centre of mass; one OBJ object `material_<id>` per material, so
//!   any viewer opens it and the material of each face survives.
//!
//! Packages are written by `spacepose target prepare` (crate
//! `spacepose-prepare`), which also calibrates them; this module only reads
//! and writes them, so every service can load one without simulating.
//! The decision and its reasons are in `docs/design/target-packages.md`.

mod io;
mod manifest;
mod obj;

pub use io::{
    MANIFEST_FILE, MESH_FILE, is_package_dir, load_package, parse_manifest, write_package,
};
pub use manifest::{
    Calibration, CalibrationRecord, Geometry, MaterialRecord, MeshRecord, PACKAGE_FORMAT,
    PackageManifest, Provenance, SymmetryRecord,
};

use crate::target::Target;
use std::path::PathBuf;

/// The package's subdirectory for its CNN (`model.onnx`, `model.json`),
/// written by `spacepose train --target DIR`.
pub const CNN_DIR: &str = "cnn";

impl TargetPackage {
    /// The package's CNN directory when it holds a model (`None` for an
    /// embedded built-in or a package without one).
    pub fn cnn_dir(&self) -> Option<PathBuf> {
        let dir = self.dir.as_ref()?.join(CNN_DIR);
        dir.join("model.onnx").is_file().then_some(dir)
    }
}

/// A loaded target package: the target and its manifest.
#[derive(Clone, Debug)]
pub struct TargetPackage {
    /// The target (mesh, materials, symmetry group, twins).
    pub target: Target,
    /// What the package records about it.
    pub manifest: PackageManifest,
    /// The directory it was loaded from (`None` for an embedded built-in).
    pub dir: Option<PathBuf>,
}

#[cfg(test)]
#[path = "package_tests.rs"]
mod tests;
