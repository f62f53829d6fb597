//! Target spacecraft models: meshes, built-in targets, materials, symmetries, surface sampling
//! and BVH ray casting.
//!
//! A [`Target`] holds a triangle [`Mesh`] in the target body frame (origin at the centre of
//! mass), one [`Material`] per [`MaterialId`] used by its faces, and its symmetry group (the
//! rotations `S_k` with `Q ≡ Q S_k`, seed 004 Eq. (14)). Built-in targets: ENVISAT (seed 002
//! §3.1) and a DEOS-like client (seed 004 §III.C.4). Other targets load from STL, OBJ or PLY.
#![forbid(unsafe_code)]

pub mod as_built;
pub mod builtin;
pub mod consistency;
mod error;
mod loaders;
pub mod material;
mod mesh;
pub mod package;
pub mod sampling;
mod shapes;
pub mod symmetry;
mod target;
pub mod zoo;

pub use as_built::AsBuilt;
pub use consistency::{RangeMargin, RayConsistency, ray_consistency};
pub use error::TargetError;
pub use material::{Material, MaterialClass, MaterialId};
pub use mesh::{Mesh, RayHit};
pub use symmetry::{SymmetryOptions, SymmetryReport, detect_symmetries};
pub use target::Target;

#[cfg(test)]
mod ray_cost_tests;
