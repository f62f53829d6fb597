//! The model cloud of point-to-point ICP ([`IcpModel`]) and its
//! nearest-point lookups: the exact voxel grid, the kd-tree and the
//! optional approximate far grids.

use super::far_grid::FarGrid;
use super::point_grid::PointGrid;
use crate::error::RegistrationError;
use crate::kdtree::{Tree3, build_tree};
use crate::params::CellLookup;
use crate::params::check_positive;
use kiddo::SquaredEuclidean;
use nalgebra::Vector3;

/// Distance the default lookup grid of [`IcpModel::new`] is exact for (m):
/// Table 1's ICP correspondence distance.
pub const DEFAULT_GRID_MAX_DISTANCE_M: f64 = 0.10;
/// Voxel edge of the default lookup grid (m).
pub const DEFAULT_GRID_RESOLUTION_M: f64 = 0.03;
/// Upper bound on the number of lookup-grid voxels (memory guard); the
/// voxel edge is coarsened until the grid fits.
pub const MAX_GRID_VOXELS: usize = 1 << 23;

/// Figures describing the lookup grid of an [`IcpModel`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IcpLookupStats {
    /// Voxel edge actually used (m).
    pub resolution_m: f64,
    /// Grid dimensions.
    pub dims: [u32; 3],
    /// Distance the grid is exact for (m).
    pub max_distance_m: f64,
    /// Candidate entries over all voxels.
    pub candidates: usize,
    /// Voxels with at least one candidate.
    pub non_empty_voxels: usize,
}

/// The model cloud with its kd-tree and its exact nearest-point lookup
/// grid, built once per target.
#[derive(Debug)]
pub struct IcpModel {
    points: Vec<Vector3<f64>>,
    tree: Tree3,
    pub(super) grid: PointGrid,
    /// The approximate lookups of wide searches, finest first, if added
    /// ([`IcpModel::with_far_lookup`]).
    far: Vec<FarGrid>,
}

/// Figures describing one level of the approximate far lookup of an
/// [`IcpModel`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IcpFarLookupStats {
    /// Voxel edge actually used (m); answers are at most about 2 times
    /// this farther than the nearest model point (√3 edges, plus the
    /// fill's propagation errors).
    pub resolution_m: f64,
    /// Voxels in the grid.
    pub voxels: usize,
}

impl IcpModel {
    /// Builds the kd-tree and the default lookup grid (exact within
    /// [`DEFAULT_GRID_MAX_DISTANCE_M`]) over `model` (target body frame, m).
    /// The points are kept rounded to f32 (a shift below 0.2 µm within
    /// 2 m of the origin), for the compact grid; both lookups see the same
    /// rounded points.
    ///
    /// Errors: fewer than 3 points, or a non-finite point.
    pub fn new(model: &[Vector3<f64>]) -> Result<Self, RegistrationError> {
        Self::with_grid(
            model,
            DEFAULT_GRID_MAX_DISTANCE_M,
            DEFAULT_GRID_RESOLUTION_M,
        )
    }

    /// [`IcpModel::new`] with a lookup grid exact within
    /// `grid_max_distance_m`, of voxel edge `grid_resolution_m`. Queries
    /// with a larger correspondence distance use the kd-tree.
    ///
    /// Errors: those of [`IcpModel::new`], and a non-finite or
    /// non-positive distance or edge.
    pub fn with_grid(
        model: &[Vector3<f64>],
        grid_max_distance_m: f64,
        grid_resolution_m: f64,
    ) -> Result<Self, RegistrationError> {
        check_positive("grid_max_distance_m", grid_max_distance_m)?;
        check_positive("grid_resolution_m", grid_resolution_m)?;
        if model.len() < 3 {
            return Err(RegistrationError::InvalidModel(format!(
                "{} points, at least 3 needed",
                model.len()
            )));
        }
        if model.len() > u32::MAX as usize {
            return Err(RegistrationError::InvalidModel(format!(
                "{} points, at most {} supported",
                model.len(),
                u32::MAX
            )));
        }
        // f32-exact points (lidar clouds are f32 anyway): the grid stores
        // its candidates in f32, and kd-tree and grid see the same points.
        let points: Vec<Vector3<f64>> = model
            .iter()
            .map(|p| p.map(|v| f64::from(v as f32)))
            .collect();
        if let Some(i) = points.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
            return Err(RegistrationError::InvalidModel(format!(
                "point {i} is not finite (in f32)"
            )));
        }
        let tree = build_tree(&points)?;
        let grid = PointGrid::build(
            &points,
            &tree,
            grid_max_distance_m,
            grid_resolution_m,
            MAX_GRID_VOXELS,
        );
        Ok(Self {
            points,
            tree,
            grid,
            far: Vec::new(),
        })
    }

    /// Adds a level of approximate nearest-point lookup for wide searches
    /// (see [`IcpParams::far_lookup_from_m`]): a voxel grid of edge
    /// `resolution_m` (coarsened to at most [`MAX_GRID_VOXELS`]) over the
    /// model's bounding box widened by `margin_m`, each voxel answering
    /// with the model point nearest to its centre (filled here, by
    /// nearest-point propagation: ~0.2 s for 2 million voxels).
    /// An answer is at most about 2 edges farther than the true nearest
    /// point. Levels are tried in the order they were added, so
    /// add a fine grid with a small margin first, then coarser ones with
    /// wider margins: a query beyond a fine grid's margin is at least that
    /// margin from every model point, where a coarser answer costs less
    /// in relative terms. A query outside every level has no model point
    /// within the widest margin: a search limited to that distance or less
    /// finds none at once; a wider one uses the kd-tree.
    ///
    /// Errors: a non-finite or non-positive edge, a negative or
    /// non-finite margin.
    ///
    /// [`IcpParams::far_lookup_from_m`]: crate::params::IcpParams::far_lookup_from_m
    pub fn with_far_lookup(
        mut self,
        margin_m: f64,
        resolution_m: f64,
    ) -> Result<Self, RegistrationError> {
        check_positive("far lookup resolution_m", resolution_m)?;
        if !(margin_m.is_finite() && margin_m >= 0.0) {
            return Err(RegistrationError::param(
                "far lookup margin_m",
                "must be finite and >= 0",
            ));
        }
        self.far.push(FarGrid::new(
            &self.points,
            margin_m,
            resolution_m,
            MAX_GRID_VOXELS,
        ));
        Ok(self)
    }

    /// Figures describing each level of the far lookup, in query order.
    pub fn far_lookup_stats(&self) -> Vec<IcpFarLookupStats> {
        self.far
            .iter()
            .map(|f| IcpFarLookupStats {
                resolution_m: f.resolution(),
                voxels: f.len(),
            })
            .collect()
    }

    /// The answer of the first far-lookup level that covers `q`, else the
    /// kd-tree's.
    #[inline]
    fn nearest_far(&self, q: &Vector3<f64>) -> (Vector3<f64>, f64) {
        self.far
            .iter()
            .find_map(|grid| grid.nearest(q, &self.points))
            .unwrap_or_else(|| self.nearest(q))
    }

    /// Number of model points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True when the model has no point (never the case once built).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Figures describing the lookup grid.
    pub fn lookup_stats(&self) -> IcpLookupStats {
        let (resolution_m, dims, candidates, non_empty_voxels) = self.grid.stats();
        IcpLookupStats {
            resolution_m,
            dims,
            max_distance_m: self.grid.max_distance,
            candidates,
            non_empty_voxels,
        }
    }

    /// The squared distance from `q` (target body frame, m) to the nearest
    /// model point, exactly (lookup grid when a point is within its
    /// distance, kd-tree otherwise). For scoring a pose point by point,
    /// e.g. a trimmed f_CONV.
    pub fn squared_distance_m2(&self, q: &Vector3<f64>) -> f64 {
        self.nearest_any(q, CellLookup::Grid, false).1
    }

    /// The nearest model point to `q` and the squared distance (kd-tree).
    #[inline]
    pub(super) fn nearest(&self, q: &Vector3<f64>) -> (Vector3<f64>, f64) {
        let hit = self
            .tree
            .query(&[q.x, q.y, q.z])
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        (self.points[hit.item as usize], hit.distance)
    }

    /// The nearest model point to `q` and the squared distance, if within
    /// `max_distance_m`. [`CellLookup::Grid`] uses the grid when
    /// `max_distance_m` does not exceed the distance it was built for;
    /// otherwise, and for [`CellLookup::KdTree`], the kd-tree answers. Both
    /// are exact. With `far` and a far lookup, the far lookup answers
    /// instead of the kd-tree (approximately).
    #[inline]
    pub(super) fn nearest_within(
        &self,
        q: &Vector3<f64>,
        max_distance_m: f64,
        lookup: CellLookup,
        far: bool,
    ) -> Option<(Vector3<f64>, f64)> {
        let max2 = max_distance_m * max_distance_m;
        if lookup == CellLookup::Grid && max_distance_m <= self.grid.max_distance {
            return self.grid.nearest_within(q, max2);
        }
        let (m, d2) = if far {
            match self
                .far
                .iter()
                .find_map(|grid| grid.nearest(q, &self.points))
            {
                Some(hit) => hit,
                // Outside a grid whose margin reaches max_distance_m: no
                // model point is that close (exact, and no kd-tree search).
                None if self.far.iter().any(|g| g.margin() >= max_distance_m) => return None,
                None => self.nearest(q),
            }
        } else {
            self.nearest(q)
        };
        (d2 <= max2).then_some((m, d2))
    }

    /// The nearest model point to `q` and the squared distance, with no
    /// distance limit: the grid when it has a point within its distance,
    /// the kd-tree otherwise (or always, for [`CellLookup::KdTree`]).
    /// With `far`, the far lookup replaces the kd-tree (approximately).
    #[inline]
    pub(super) fn nearest_any(
        &self,
        q: &Vector3<f64>,
        lookup: CellLookup,
        far: bool,
    ) -> (Vector3<f64>, f64) {
        if lookup == CellLookup::Grid {
            let max = self.grid.max_distance;
            if let Some(hit) = self.grid.nearest_within(q, max * max) {
                return hit;
            }
        }
        self.nearest_beyond_grid(q, far)
    }

    /// [`IcpModel::nearest_any`]'s answer when the grid has none: the far
    /// lookup with `far`, the kd-tree otherwise.
    #[inline]
    pub(super) fn nearest_beyond_grid(&self, q: &Vector3<f64>, far: bool) -> (Vector3<f64>, f64) {
        if far {
            self.nearest_far(q)
        } else {
            self.nearest(q)
        }
    }
}
