//! Symmetry detection from a mesh: the proper rotations `S` that map the
//! surface onto itself (seed 004 §III.C.4, Eq. (14): attitude `Q` is
//! equivalent to `Q S`), and the near-symmetric twins.
//!
//! # Method
//! The mesh is in the body frame, its origin at the centre of mass, so every
//! symmetry is a rotation about an axis through the origin. All lengths are
//! fractions of the bounding radius `R` (the largest vertex norm), so the
//! method is scale-free.
//!
//! 1. **Principal axes.** The area-weighted second moment of the surface,
//!    `M = ∫ p pᵀ dA`, is computed exactly per triangle. A symmetry `S`
//!    maps the surface onto itself, so `S M Sᵀ = M`: it permutes the
//!    eigenspaces of `M`. Hence:
//!    - three distinct moments: `S` is diagonal (±1) in the principal frame,
//!      a half-turn about a principal axis;
//!    - two equal moments: `S` keeps the line of the third axis, so it is a
//!      rotation about that axis (any order), or a half-turn about an axis
//!      of the degenerate plane (a dihedral 2-fold axis): a rotation by θ
//!      about an in-plane axis keeps the main axis on its line only for θ = π;
//!    - three equal moments (cube, tetrahedron, icosahedron...): no axis is
//!      preferred.
//!
//!    Moments count as equal within `2 · twin_fraction` of the trace: exact
//!    symmetries make them exactly equal; the margin lets near-symmetric
//!    twins be found too.
//! 2. **Candidate axes.** Axes that may carry any order get the angles
//!    `2πk/n`, `n = 2..=max_order`, `k` prime to `n`: the three principal
//!    axes when the moments are distinct (an exact symmetry is then a
//!    half-turn, but a twin need not be: trying every order costs little),
//!    the main axis when two moments are equal. Half-turn axes
//!    of a degenerate plane come from the vertices: the half-turn about an
//!    in-plane line `u` acts on the vertices projected on the plane as the
//!    mirror across `u` and keeps each vertex's distance from the main axis,
//!    so each level of that distance is a mirror-symmetric set of directions
//!    and `u` passes through one of them or bisects two angular neighbours.
//!    The outermost level is always made of vertices (the surface points
//!    farthest from a line are vertices), so it holds for any tessellation;
//!    inner levels add axes for twins (at most 180 directions, each with its
//!    bisector). With three equal moments, the candidate axes are the
//!    directions of the farthest vertices (any symmetry permutes them), with
//!    every order, and the sums of pairs of them, as half-turns (a half-turn
//!    maps `v` to `w` only about the line of `v + w`); the group closure
//!    below supplies the remaining axes (e.g. the 4-fold axes of a cube).
//! 3. **Confirmation by surface distance.** A rotation is scored by the
//!    distance from the rotated surface samples to the mesh surface (BVH
//!    point projection). The samples are at most `max_samples` area-uniform
//!    points plus at most as many mesh vertices (which catch small features
//!    that few area samples hit), in a seeded random order. Since a rotation
//!    keeps area, `S(surface) ⊆ surface` already means equality, so the
//!    one-sided distance suffices. Verdicts: every distance within
//!    `tolerance_fraction · R` → symmetry; otherwise the [`TWIN_QUANTILE`]
//!    quantile of the area samples within `twin_fraction · R` → twin (most of
//!    the surface maps onto itself; the rest is the feature that tells the
//!    twin apart). Pruning: each candidate first gets at most 256 area
//!    samples, stopping as soon as the share beyond the twin bound is
//!    clearly (4σ of a binomial count) above `1 − TWIN_QUANTILE`: a wrong
//!    rotation costs about ten distance queries. Full checks stop at the
//!    first sample beyond the tolerance; a twin is accepted as soon as, after
//!    400 samples, the share is clearly below its limit.
//! 4. **Group.** Candidates symmetric on the first look, the most exact
//!    first, join the group one at a time: the group is regenerated (all
//!    products, deduplicated within `tolerance_fraction` rad, the angle under
//!    which two rotations move no point by more than the tolerance), and the
//!    candidate and each new element are confirmed on the full sample. A
//!    candidate is left out if the group it generates would exceed
//!    max(60, 2 · max_order) elements or hold an element of order above
//!    `max_order` (checked before any distance query): this only happens
//!    close to a continuous symmetry (a finely tessellated cylinder), where
//!    the result is the largest such finite group found greedily, and the
//!    rotation goes on to the twin stage. The identity comes first, then the
//!    elements by increasing angle.
//! 5. **Twins.** The remaining candidates that map most of the surface, by
//!    increasing mean error, become twins unless
//!    - they lie within `twin_fraction` rad of the group or of the class
//!      `T·group` of a listed twin `T` (`F` and `F S` are the same twin), or
//!    - they are not a pose of their own: halfway between the rotation and
//!      the nearest element of the group or of a listed class, the surface
//!      fits no worse (mean distance not larger by more than the tolerance).
//!      A small rotation always passes the quantile test (it moves every
//!      point a little), and so does a rotation by a few degrees off a
//!      symmetry or a twin; a true twin lies in a basin of its own.
//!
//!    Each kept class is listed by its member with the smallest angle; at
//!    most [`MAX_TWINS`].
//!
//! Limits: rotations of order above `max_order` are not tried (a 24-gonal
//! cylinder shows at most the 12-fold subgroup with the default options);
//! a symmetry whose axis is none of the candidates above and is not a
//! product of found ones is missed (this needs three equal moments and fewer
//! farthest vertices than its orbit); a centre of mass off the shape's
//! centre of symmetry hides the symmetry, by design.

mod axes;
mod classify;
mod confirm;
mod group;
mod options;

pub use options::{
    CandidateScore, MAX_TWINS, SymmetryOptions, SymmetryReport, TWIN_QUANTILE, Verdict,
};

use crate::error::TargetError;
use crate::mesh::Mesh;

/// Detects the symmetry group and the near-symmetric twins of `mesh`, given
/// in the body frame (origin at the centre of mass). See the module
/// documentation for the method.
///
/// Errors: invalid `options` ([`SymmetryOptions::validate`]), or a mesh whose
/// vertices are all at the origin or that gives no surface sample.
pub fn detect_symmetries(
    mesh: &Mesh,
    options: &SymmetryOptions,
) -> Result<SymmetryReport, TargetError> {
    options.validate()?;
    let radius = mesh.vertices().iter().map(|v| v.norm()).fold(0.0, f64::max);
    if !(radius.is_finite() && radius > 0.0) {
        return Err(TargetError::InvalidMesh(format!(
            "bounding radius {radius} m: no symmetry to detect"
        )));
    }
    let scorer = confirm::Scorer::new(mesh, options, radius)?;
    let moments = axes::classify_moments(&axes::second_moment(mesh), 2.0 * options.twin_fraction);
    let level = options.tolerance_fraction * radius;
    let candidates = axes::candidate_rotations(mesh, &moments, options.max_order, radius, level);
    let classified = classify::classify(&candidates, &scorer, options);
    Ok(SymmetryReport {
        group: group::canonical_order(classified.group, options.tolerance_fraction),
        twins: classified.twins,
        candidates: classified.scores,
        bounding_radius_m: radius,
        samples: scorer.sizes(),
    })
}

#[cfg(test)]
#[path = "detect_tests.rs"]
mod tests;
