//! Errors of the target crate.

use std::path::PathBuf;

/// Everything that can go wrong when building, loading or sampling a target model.
#[derive(Debug, thiserror::Error)]
pub enum TargetError {
    /// The mesh file could not be opened or parsed.
    #[error("cannot read mesh file {path}: {message}")]
    Read {
        /// Path of the file.
        path: PathBuf,
        /// What the reader reported.
        message: String,
    },
    /// The file extension is not one of `.stl`, `.obj`, `.ply` (case-insensitive).
    #[error("unsupported mesh file {path}: expected a .stl, .obj or .ply extension")]
    UnknownExtension {
        /// Path of the file.
        path: PathBuf,
    },
    /// The file was read but its content is not a usable mesh (empty, NaN vertices, bad indices...).
    #[error("invalid mesh in {path}: {message}")]
    InvalidFile {
        /// Path of the file.
        path: PathBuf,
        /// Why the mesh was rejected.
        message: String,
    },
    /// The scale factor applied to a loaded mesh is not finite and strictly positive.
    #[error("invalid scale {scale} for {spec}: must be finite and > 0")]
    InvalidScale {
        /// The path or target name the scale was meant for.
        spec: String,
        /// The rejected scale.
        scale: f64,
    },
    /// A mesh built in memory is invalid (empty, non-finite vertex, index out of range,
    /// material list of the wrong length, zero total area).
    #[error("invalid mesh: {0}")]
    InvalidMesh(String),
    /// A target's parts are inconsistent (material id without a material, bad symmetry list).
    #[error("invalid target '{name}': {message}")]
    InvalidTarget {
        /// Name of the target.
        name: String,
        /// What is inconsistent.
        message: String,
    },
    /// The name is not one of [`crate::Target::BUILTIN`].
    #[error("unknown built-in target '{0}' (built-in targets: envisat, deos)")]
    UnknownBuiltin(String),
    /// The sampling spacing is not finite and strictly positive, or would give too many points.
    #[error("invalid surface sampling spacing {spacing_m} m: {message}")]
    InvalidSpacing {
        /// The rejected spacing (m).
        spacing_m: f64,
        /// Why it was rejected.
        message: String,
    },
    /// A target package (directory or embedded manifest) is malformed: bad
    /// manifest, unknown format, mesh file not in the package subset, or an
    /// invalid calibration.
    #[error("invalid target package: {0}")]
    InvalidPackage(String),
    /// Symmetry detection options out of range (see
    /// [`crate::symmetry::SymmetryOptions::validate`]).
    #[error("invalid symmetry options: {0}")]
    InvalidSymmetryOptions(String),
}
