//! The smoothed NDT map of seed 000 §3.1: a kd-tree partition of the model
//! cloud into cells, one normal distribution per cell, the Gaussian
//! smoothing of Eq. (1)-(2), precomputed inverse covariances, and an exact
//! nearest-cell lookup.

mod file;
pub use file::{MAP_FORMAT_VERSION, MAP_MAGIC};
mod gaussian;
mod lookup;
mod partition;
mod smoothing;

use crate::error::RegistrationError;
use crate::kdtree::{Tree3, build_tree};
use crate::params::{CellLookup, NdtMapParams};
use gaussian::{EigenFloor, mean_covariance};
use kiddo::SquaredEuclidean;
use lookup::LookupGrid;
use nalgebra::{Matrix3, Vector3};
use smoothing::RawCell;

/// Fewest finite model points a map is built from.
pub const MIN_MODEL_POINTS: usize = 4;

/// One smoothed cell of the map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NdtCell {
    /// Smoothed mean `μ̃` (model frame, m).
    pub mean: Vector3<f64>,
    /// Smoothed, regularised covariance `C̃` (m²).
    pub covariance: Matrix3<f64>,
    /// `C̃⁻¹` (m⁻²).
    pub inv_covariance: Matrix3<f64>,
    /// Number of model points in the kd-tree leaf before smoothing.
    pub points: u32,
}

/// Figures describing a built map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NdtMapStats {
    /// Number of cells.
    pub cells: usize,
    /// Number of model points the map was built from.
    pub model_points: usize,
    /// Edge of a lookup-grid voxel actually used (m).
    pub lookup_resolution_m: f64,
    /// Lookup-grid dimensions.
    pub lookup_dims: [u32; 3],
    /// Voxels with at least one candidate cell.
    pub lookup_non_empty_voxels: usize,
    /// Mean number of candidate cells per non-empty voxel.
    pub lookup_mean_candidates: f64,
}

/// The smoothed NDT map. Build it once per target model
/// ([`NdtMap::build`]), or [`NdtMap::load`] a saved one.
#[derive(Debug)]
pub struct NdtMap {
    params: NdtMapParams,
    model_points: usize,
    means: Vec<Vector3<f64>>,
    covariances: Vec<Matrix3<f64>>,
    inv_covariances: Vec<Matrix3<f64>>,
    counts: Vec<u32>,
    /// Unit normal of each cell: the eigenvector of the smallest eigenvalue
    /// of its smoothed covariance (derived, not stored in map files).
    normals: Vec<Vector3<f64>>,
    grid: LookupGrid,
    tree: Tree3,
}

/// The unit normal of each covariance (eigenvector of its smallest
/// eigenvalue).
pub(crate) fn normals_of(covariances: &[Matrix3<f64>]) -> Vec<Vector3<f64>> {
    covariances
        .iter()
        .map(|c| {
            let e = c.symmetric_eigen();
            let i = e.eigenvalues.imin();
            e.eigenvectors.column(i).normalize()
        })
        .collect()
}

impl NdtMap {
    /// Builds the smoothed NDT map of a model cloud (model frame, m).
    ///
    /// Steps (seed 000 §3.1): kd-tree partition by median splits along the
    /// widest axis down to `min_cell_size_m`; mean and covariance per leaf,
    /// eigenvalue-floored (see [`NdtMapParams::eigen_floor_rel`]); Gaussian
    /// smoothing of every cell over the cells whose mean lies within
    /// `smoothing_radius_sigmas · σ` of its centre (Eq. 1-2); the smoothed
    /// covariance is floored again and inverted; finally the nearest-cell
    /// lookup grid and kd-tree over the smoothed means are built.
    ///
    /// Errors: invalid parameters; an empty model, fewer than
    /// [`MIN_MODEL_POINTS`] points, or any non-finite point.
    pub fn build(model: &[Vector3<f64>], params: &NdtMapParams) -> Result<Self, RegistrationError> {
        params.validate()?;
        if model.len() < MIN_MODEL_POINTS {
            return Err(RegistrationError::InvalidModel(format!(
                "{} points, at least {MIN_MODEL_POINTS} needed",
                model.len()
            )));
        }
        if let Some(i) = model.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
            return Err(RegistrationError::InvalidModel(format!(
                "point {i} is not finite"
            )));
        }
        let floor = EigenFloor {
            rel: params.eigen_floor_rel,
            abs_sigma: params.eigen_floor_abs_m,
        };
        let (order, leaves) =
            partition::partition(model, params.min_cell_size_m, params.min_points_per_cell);
        let raw: Vec<RawCell> = leaves
            .iter()
            .map(|leaf| {
                let (mean, cov) = mean_covariance(model, &order[leaf.start..leaf.end]);
                let covariance = floor.apply(&cov).map_or(cov, |(c, _)| c);
                RawCell {
                    mean,
                    covariance,
                    count: (leaf.end - leaf.start) as u32,
                    centre: leaf.centre,
                }
            })
            .collect();
        let sigma = params.smoothing_sigma_m;
        let smoothed = smoothing::smooth(&raw, sigma, params.smoothing_radius_sigmas * sigma)?;
        let mut means = Vec::with_capacity(smoothed.len());
        let mut covariances = Vec::with_capacity(smoothed.len());
        let mut inv_covariances = Vec::with_capacity(smoothed.len());
        for (mean, cov) in smoothed {
            let (c, inv) = floor.apply(&cov).ok_or_else(|| {
                RegistrationError::InvalidModel("non-finite smoothed covariance".into())
            })?;
            means.push(mean);
            covariances.push(c);
            inv_covariances.push(inv);
        }
        let counts = raw.iter().map(|c| c.count).collect();
        let grid = LookupGrid::build(
            &means,
            params.lookup_max_distance_m,
            params.lookup_resolution_m,
            params.max_lookup_voxels,
        );
        let tree = build_tree(&means)?;
        let normals = normals_of(&covariances);
        Ok(Self {
            params: *params,
            model_points: model.len(),
            means,
            covariances,
            inv_covariances,
            counts,
            normals,
            grid,
            tree,
        })
    }

    /// The parameters the map was built with.
    pub fn params(&self) -> &NdtMapParams {
        &self.params
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.means.len()
    }

    /// True when the map has no cell (never the case for a built map).
    pub fn is_empty(&self) -> bool {
        self.means.is_empty()
    }

    /// Cell `k`, if it exists.
    pub fn cell(&self, k: usize) -> Option<NdtCell> {
        Some(NdtCell {
            mean: *self.means.get(k)?,
            covariance: self.covariances[k],
            inv_covariance: self.inv_covariances[k],
            points: self.counts[k],
        })
    }

    /// The smoothed cell means.
    pub fn means(&self) -> &[Vector3<f64>] {
        &self.means
    }

    /// Figures describing the map and its lookup grid.
    pub fn stats(&self) -> NdtMapStats {
        let (mean_candidates, non_empty) = self.grid.occupancy();
        NdtMapStats {
            cells: self.len(),
            model_points: self.model_points,
            lookup_resolution_m: self.grid.resolution,
            lookup_dims: self.grid.dims,
            lookup_non_empty_voxels: non_empty,
            lookup_mean_candidates: mean_candidates,
        }
    }

    /// The cell whose smoothed mean is nearest to `q`, with the squared
    /// distance, if that distance is at most `max_distance_m` (η(i) of
    /// Eq. 3). [`CellLookup::Grid`] is used only when `max_distance_m` does
    /// not exceed the distance the grid was built for; otherwise, and for
    /// [`CellLookup::KdTree`], the kd-tree answers. Both are exact.
    #[inline]
    pub fn nearest_cell(
        &self,
        q: &Vector3<f64>,
        max_distance_m: f64,
        lookup: CellLookup,
    ) -> Option<(usize, f64)> {
        let max2 = max_distance_m * max_distance_m;
        if lookup == CellLookup::Grid && max_distance_m <= self.grid.max_distance {
            let mut best = (usize::MAX, max2);
            for c in self.grid.candidates_at(q) {
                let (dx, dy, dz) = (c.mean[0] - q.x, c.mean[1] - q.y, c.mean[2] - q.z);
                let d2 = dx * dx + dy * dy + dz * dz;
                if d2 <= best.1 {
                    best = (c.cell as usize, d2);
                }
            }
            return (best.0 != usize::MAX).then_some(best);
        }
        if !q.iter().all(|v| v.is_finite()) {
            return None;
        }
        let hit = self
            .tree
            .query(&[q.x, q.y, q.z])
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        (hit.distance <= max2).then_some((hit.item as usize, hit.distance))
    }

    /// `(μ̃_k, n_k)`: the mean and unit normal of cell `k`.
    #[inline]
    pub(crate) fn mean_and_normal(&self, k: usize) -> (&Vector3<f64>, &Vector3<f64>) {
        (&self.means[k], &self.normals[k])
    }

    /// `(μ̃_k, C̃_k⁻¹)` without bounds checks beyond the slice's own.
    #[inline]
    pub(crate) fn mean_and_information(&self, k: usize) -> (&Vector3<f64>, &Matrix3<f64>) {
        (&self.means[k], &self.inv_covariances[k])
    }
}

#[cfg(test)]
mod tests;
