//! Target packages for any spacecraft: [`prepare`] turns a mesh (or a
//! built-in target) into a package directory, and [`resolve`] turns what a
//! user writes where a target is expected (a built-in name, a package
//! directory or a mesh file) into a loaded package.
//!
//! Preparing a package:
//! 1. loads the mesh (STL, OBJ, PLY, scaled to metres, origin moved to the
//!    area-weighted centroid) and records its conventions and geometry;
//! 2. detects its symmetry group and near-symmetric twins from the surface
//!    ([`spacepose_model::symmetry`]), unless the user overrides them;
//! 3. calibrates the shape-dependent thresholds by simulating this target
//!    with the Mid-40 model, every sensor effect on, and registering each
//!    frame from its true pose ([`calibrate`]); truth is used here, at
//!    prepare time, and never at run time;
//! 4. writes `target.toml` and `mesh.obj` ([`spacepose_model::package`]).
//!
//! A mesh path given where a package is expected is prepared on first use
//! and cached (see [`resolve`]). The decisions are in
//! `docs/design/target-packages.md`.
#![forbid(unsafe_code)]

pub mod calibrate;
mod error;
mod fnv;
pub mod prepare;
pub mod resolve;

pub use calibrate::{CalibrationOptions, calibrate};
pub use error::PrepareError;
pub use prepare::{PrepareOptions, SymmetryChoice, length_unit_m, prepare};
pub use resolve::{builtin_package, cache_dir, resolve, resolve_in};
