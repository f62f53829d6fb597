//! Options and results of symmetry detection.

use nalgebra::{Rotation3, Vector3};

use crate::error::TargetError;

/// Share of the surface area that a twin must map within
/// [`SymmetryOptions::twin_fraction`] of the mesh: its error at this quantile
/// is the one compared (the remaining tenth is where the features that tell
/// the twin apart may sit).
pub const TWIN_QUANTILE: f64 = 0.9;

/// Largest number of twins a report lists (the best first). Only a body
/// close to a continuous symmetry (a finely tessellated cylinder or sphere)
/// reaches it.
pub const MAX_TWINS: usize = 24;

/// Settings of [`crate::symmetry::detect_symmetries`]. Every length is a
/// fraction of the bounding radius `R` (the largest vertex distance from the
/// body origin), so the same options fit a 1 m and a 30 m target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SymmetryOptions {
    /// A rotation is a symmetry when no surface sample moved by it lies
    /// farther than `tolerance_fraction · R` from the mesh surface. Also the
    /// angle (rad) under which two rotations count as the same. In (0, 0.1].
    pub tolerance_fraction: f64,
    /// A rotation that is not a symmetry is a twin when the
    /// [`TWIN_QUANTILE`] quantile of the moved samples' distances is at most
    /// `twin_fraction · R`. Also the angle (rad) under which two twins count
    /// as the same near-symmetry. In [`tolerance_fraction`, 0.5].
    ///
    /// [`tolerance_fraction`]: SymmetryOptions::tolerance_fraction
    pub twin_fraction: f64,
    /// Highest order `n` of the candidate rotations `2πk/n` about an axis,
    /// and of any element of the detected group. In 2..=48.
    pub max_order: u32,
    /// Spacing of the surface samples as a fraction of `R`, before the
    /// [`max_samples`](SymmetryOptions::max_samples) cap widens it. In (0, 0.5].
    pub sample_spacing_fraction: f64,
    /// Most area samples scored, and most mesh vertices scored besides them
    /// (vertices catch small features that few area samples land on). In
    /// 100..=100000.
    pub max_samples: usize,
    /// Seed of the surface sampling and of the sample order.
    pub seed: u64,
}

impl Default for SymmetryOptions {
    /// 0.5 % of `R` for a symmetry, 5 % of `R` for a twin, orders up to 12,
    /// samples every 1 % of `R` but at most 2000 (and 2000 vertices), seed 1.
    fn default() -> Self {
        SymmetryOptions {
            tolerance_fraction: 0.005,
            twin_fraction: 0.05,
            max_order: 12,
            sample_spacing_fraction: 0.01,
            max_samples: 2000,
            seed: 1,
        }
    }
}

impl SymmetryOptions {
    /// Checks every field against the range its documentation gives; NaN
    /// and infinities are rejected.
    pub fn validate(&self) -> Result<(), TargetError> {
        let bad = |message: String| Err(TargetError::InvalidSymmetryOptions(message));
        let in_range = |x: f64, lo: f64, hi: f64| x.is_finite() && x > lo && x <= hi;
        if !in_range(self.tolerance_fraction, 0.0, 0.1) {
            return bad(format!(
                "tolerance_fraction {} must be in (0, 0.1]",
                self.tolerance_fraction
            ));
        }
        if !(self.twin_fraction.is_finite()
            && self.twin_fraction >= self.tolerance_fraction
            && self.twin_fraction <= 0.5)
        {
            return bad(format!(
                "twin_fraction {} must be in [tolerance_fraction = {}, 0.5]",
                self.twin_fraction, self.tolerance_fraction
            ));
        }
        if !(2..=48).contains(&self.max_order) {
            return bad(format!("max_order {} must be in 2..=48", self.max_order));
        }
        if !in_range(self.sample_spacing_fraction, 0.0, 0.5) {
            return bad(format!(
                "sample_spacing_fraction {} must be in (0, 0.5]",
                self.sample_spacing_fraction
            ));
        }
        if !(100..=100_000).contains(&self.max_samples) {
            return bad(format!(
                "max_samples {} must be in 100..=100000",
                self.max_samples
            ));
        }
        Ok(())
    }
}

/// What became of a candidate rotation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// In the detected symmetry group.
    Symmetry,
    /// Listed in [`SymmetryReport::twins`] (as itself or as the member of its
    /// class with the smallest angle). Also a rotation within the tolerance
    /// that could not join a finite group (see [`crate::symmetry`], step 4).
    Twin,
    /// Maps most of the surface onto it, but adds nothing: it lies within
    /// the twin angle ([`SymmetryOptions::twin_fraction`] rad) of a group
    /// element or of the class of a listed twin, or in the same basin as one
    /// (halfway to it, the surface fits no worse).
    Covered,
    /// Maps most of the surface onto it but was not scored in full, because
    /// [`MAX_TWINS`] twins were already listed.
    Skipped,
    /// Neither a symmetry nor a twin.
    Rejected,
}

/// The score of one candidate rotation (axis through the body origin).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CandidateScore {
    /// Unit rotation axis (body frame).
    pub axis: Vector3<f64>,
    /// Rotation angle about `axis` (degrees, in (−180, 180]).
    pub angle_deg: f64,
    /// Largest distance from a moved sample to the surface (m), over the
    /// `points` scored (area samples, then vertices once those passed).
    pub max_error_m: f64,
    /// Median distance over the area samples scored (m).
    pub median_error_m: f64,
    /// [`TWIN_QUANTILE`] quantile of the distance over the area samples
    /// scored (m).
    pub quantile_error_m: f64,
    /// Number of points scored: a rejection stops early.
    pub points: usize,
    /// The outcome.
    pub verdict: Verdict,
}

/// The result of [`crate::symmetry::detect_symmetries`].
#[derive(Debug, Clone)]
pub struct SymmetryReport {
    /// The symmetry group: the identity first, closed under composition (to
    /// the tolerance angle), every element confirmed on the whole sample.
    pub group: Vec<Rotation3<f64>>,
    /// Near-symmetric twins, best first: one per class `F·group`, none in
    /// the group, each the member of its class with the smallest angle.
    pub twins: Vec<Rotation3<f64>>,
    /// Every candidate rotation tried, in the order generated.
    pub candidates: Vec<CandidateScore>,
    /// Bounding radius `R` of the mesh (m): the largest vertex norm.
    pub bounding_radius_m: f64,
    /// Number of area samples and of vertices scored per full check.
    pub samples: (usize, usize),
}
