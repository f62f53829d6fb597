//! Point-to-point ICP (Besl & McKay; seed 000 §2.1, Table 1 ICP row) against
//! the model cloud, with its nearest-point structures built once
//! ([`IcpModel`]): an exact voxel lookup grid within the correspondence
//! distance, and a kiddo kd-tree beyond it.
//!
//! Each iteration pairs every transformed point with its nearest model
//! point within `max_distance_m` and applies the closed-form optimal rigid
//! update for those pairs (Kabsch / Umeyama SVD, no scale); it stops when
//! the norm of the increment `[Log ΔR; Δp]` (left ⊕ of Eq. 5) drops below
//! `termination_increment`.

use crate::error::RegistrationError;
use crate::kdtree::{Tree3, build_tree};
use crate::normal_equations::NormalEquations;
use crate::params::check_positive;
use crate::params::{CellLookup, IcpParams};
use crate::result::{Cost, Increment, Registration};
use crate::source::{check_pose, finite_positions};
use far_grid::FarGrid;
use kiddo::SquaredEuclidean;
use nalgebra::{Matrix3, Rotation3, Vector3, Vector6};
use nearest_memo::{MemoCounts, NearestMemo};
use point_grid::PointGrid;
use spacepose_geometry::{Point, Pose, so3};

mod far_grid;
mod nearest_memo;
mod point_grid;

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
    grid: PointGrid,
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
    fn nearest(&self, q: &Vector3<f64>) -> (Vector3<f64>, f64) {
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
    fn nearest_within(
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
    fn nearest_any(&self, q: &Vector3<f64>, lookup: CellLookup, far: bool) -> (Vector3<f64>, f64) {
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
    fn nearest_beyond_grid(&self, q: &Vector3<f64>, far: bool) -> (Vector3<f64>, f64) {
        if far {
            self.nearest_far(q)
        } else {
            self.nearest(q)
        }
    }
}

/// Sums of one correspondence pass.
struct Pairs {
    x_sum: Vector3<f64>,
    m_sum: Vector3<f64>,
    /// `Σ m xᵀ` (uncentred).
    cross: Matrix3<f64>,
    count: usize,
}

/// The optimal rigid `(ΔR, Δp)` with `m ≈ ΔR x + Δp` for the pairs, or
/// `None` when the pairs are degenerate (fewer than 3, or collinear).
fn kabsch(pairs: &Pairs) -> Option<(Rotation3<f64>, Vector3<f64>)> {
    if pairs.count < 3 {
        return None;
    }
    let n = pairs.count as f64;
    let (x_bar, m_bar) = (pairs.x_sum / n, pairs.m_sum / n);
    let w = pairs.cross / n - m_bar * x_bar.transpose();
    let svd = w.svd(true, true);
    let (u, v_t) = (svd.u?, svd.v_t?);
    let s = svd.singular_values;
    let s_max = s.max();
    // Rank ≥ 2 is needed (a plane is fine, a line is not).
    let mut sorted = [s[0], s[1], s[2]];
    sorted.sort_by(|a, b| b.total_cmp(a));
    if !(s_max.is_finite() && s_max > 0.0 && sorted[1] > 1e-9 * s_max) {
        return None;
    }
    let d = (u * v_t).determinant().signum();
    let r = u * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * v_t;
    let r = Rotation3::from_matrix_unchecked(r);
    Some((r, m_bar - r * x_bar))
}

/// Reorders `points` by the 10 cm cell they fall in at pose `t` (ties in
/// their original order), so that successive lookups touch neighbouring
/// parts of the grid (cache locality; the sums only change by rounding).
fn spatial_order(points: &mut [Vector3<f64>], t: &Pose) {
    const CELL_M: f64 = 0.1;
    let key = |z: &Vector3<f64>| {
        let x = t.transform(z) / CELL_M;
        // 21 bits per axis around the origin; the order only matters for speed.
        let b = |v: f64| ((v.floor() as i64).clamp(-(1 << 20), (1 << 20) - 1) + (1 << 20)) as u64;
        (b(x.z) << 42) | (b(x.y) << 21) | b(x.x)
    };
    points.sort_by_cached_key(key);
}

/// Registers `source` (sensor frame) against `model` (target body frame)
/// by point-to-point ICP from `initial_t_target_sensor`.
///
/// The result carries `f_conv_m2` (seed 002 §4.5: mean squared distance of
/// every valid point to its nearest model point at the returned pose, no
/// distance cut), the inlier cost `Σ d²` (m²) and the information
/// `Σ JᵀJ / σ²` with `J = [-(R z)^×  I₃]` and `σ = point_sigma_m`.
///
/// Errors: invalid parameters or initial pose; empty or all-non-finite
/// cloud; no pair within `max_distance_m`; degenerate pairs (fewer than 3
/// or collinear).
pub fn register_icp(
    model: &IcpModel,
    source: &[Point],
    initial_t_target_sensor: &Pose,
    params: &IcpParams,
) -> Result<Registration, RegistrationError> {
    register_icp_counted(model, source, initial_t_target_sensor, params).0
}

/// [`register_icp`], with the lookup grid's scans and memo reuses (both
/// zero when the grid does not serve the correspondences).
pub(crate) fn register_icp_counted(
    model: &IcpModel,
    source: &[Point],
    initial_t_target_sensor: &Pose,
    params: &IcpParams,
) -> (Result<Registration, RegistrationError>, MemoCounts) {
    let mut counts = MemoCounts::default();
    let result = icp_loop(model, source, initial_t_target_sensor, params, &mut counts);
    (result, counts)
}

fn icp_loop(
    model: &IcpModel,
    source: &[Point],
    initial_t_target_sensor: &Pose,
    params: &IcpParams,
    counts: &mut MemoCounts,
) -> Result<Registration, RegistrationError> {
    params.validate()?;
    check_pose("initial_t_target_sensor", initial_t_target_sensor)?;
    let (mut points, skipped) = finite_positions(source)?;
    spatial_order(&mut points, initial_t_target_sensor);
    let mut run = IcpRun::new(model, &points, params);
    let mut pose = *initial_t_target_sensor;
    let (mut converged, mut iterations, mut last) = (false, 0, Increment::default());
    for it in 0..params.max_iterations {
        let pairs = run.pairs(&pose, counts);
        if pairs.count == 0 {
            return Err(run.no_match(it));
        }
        let (dr, dp) = kabsch(&pairs).ok_or(RegistrationError::DegenerateSystem {
            iteration: it,
            inliers: pairs.count,
        })?;
        let next = Pose::new(dr * pose.rotation, dr * pose.translation + dp);
        let rot = so3::log(&dr);
        let trans = next.translation - pose.translation;
        let eps = Vector6::new(rot.x, rot.y, rot.z, trans.x, trans.y, trans.z);
        pose = next;
        iterations = it + 1;
        last = Increment {
            rotation_rad: rot.norm(),
            translation_m: trans.norm(),
        };
        if eps.norm() < params.termination_increment {
            converged = true;
            break;
        }
    }
    let (ne, all_d2) = run.final_evaluation(&pose, counts);
    if ne.inliers == 0 {
        return Err(run.no_match(iterations));
    }
    let n = ne.inliers as f64;
    let sigma2 = params.point_sigma_m * params.point_sigma_m;
    Ok(Registration {
        t_target_sensor: pose,
        converged,
        iterations,
        cost: Cost {
            total: ne.cost,
            mean: ne.cost / n,
        },
        inliers: ne.inliers,
        valid_points: points.len(),
        skipped_non_finite: skipped,
        mean_squared_distance_m2: ne.squared_distance / n,
        f_conv_m2: Some(all_d2 / points.len() as f64),
        information: ne.hessian() / sigma2,
        last_increment: last,
        degenerate_directions: 0,
        weakest_lever_arm_m: f64::NAN,
        geometric_information: None,
    })
}

/// The correspondence search of one ICP registration: the model, the
/// (spatially ordered) source points and, within the grid's distance, a
/// nearest-neighbour memo per point.
struct IcpRun<'a> {
    model: &'a IcpModel,
    points: &'a [Vector3<f64>],
    params: &'a IcpParams,
    /// Squared maximum correspondence distance (m²).
    max2: f64,
    /// Lookups beyond `far_lookup_from_m` go through the far lookup.
    far: bool,
    /// One memo per point when memoised (see `nearest_memo`: exact, and
    /// most late lookups reuse it); empty otherwise.
    memos: Vec<NearestMemo>,
}

impl<'a> IcpRun<'a> {
    fn new(model: &'a IcpModel, points: &'a [Vector3<f64>], params: &'a IcpParams) -> Self {
        let far = params
            .far_lookup_from_m
            .is_some_and(|from| params.max_distance_m >= from);
        // Within the grid's distance every lookup goes through a memo.
        let memoised =
            params.lookup == CellLookup::Grid && params.max_distance_m <= model.grid.max_distance;
        let memos = vec![NearestMemo::default(); if memoised { points.len() } else { 0 }];
        Self {
            model,
            points,
            params,
            max2: params.max_distance_m * params.max_distance_m,
            far,
            memos,
        }
    }

    fn no_match(&self, iteration: usize) -> RegistrationError {
        RegistrationError::NoCorrespondences {
            iteration,
            max_distance_m: self.params.max_distance_m,
        }
    }

    /// The sums over every point whose nearest model point at `pose` is
    /// within the maximum correspondence distance.
    fn pairs(&mut self, pose: &Pose, counts: &mut MemoCounts) -> Pairs {
        let mut pairs = Pairs {
            x_sum: Vector3::zeros(),
            m_sum: Vector3::zeros(),
            cross: Matrix3::zeros(),
            count: 0,
        };
        let rotation = pose.rotation.matrix();
        let (model, params) = (self.model, self.params);
        for (i, z) in self.points.iter().enumerate() {
            let x = rotation * z + pose.translation;
            let hit = match self.memos.get_mut(i) {
                Some(memo) => model.grid.nearest_within_memo(&x, self.max2, memo, counts),
                None => model.nearest_within(&x, params.max_distance_m, params.lookup, self.far),
            };
            if let Some((m, _)) = hit {
                pairs.x_sum += x;
                pairs.m_sum += m;
                pairs.cross += m * x.transpose();
                pairs.count += 1;
            }
        }
        pairs
    }

    /// Final evaluation at the returned pose: the normal equations over the
    /// inliers and `Σ d²` over every point (f_CONV's numerator). Through the
    /// far lookup when the iterations used it: a wide stage's cost and
    /// f_CONV only rank and chain stages, and exact searches here cost more
    /// than its approximate iterations.
    fn final_evaluation(&mut self, pose: &Pose, counts: &mut MemoCounts) -> (NormalEquations, f64) {
        let mut ne = NormalEquations::new();
        let mut all_d2 = 0.0;
        let identity = Matrix3::identity();
        let model = self.model;
        let grid_max2 = model.grid.max_distance * model.grid.max_distance;
        for (i, z) in self.points.iter().enumerate() {
            let rz = pose.rotation * z;
            let x = rz + pose.translation;
            let (m, d2) = match self.memos.get_mut(i) {
                // The grid's answer within its distance, as `nearest_any`'s.
                Some(memo) => model
                    .grid
                    .nearest_within_memo(&x, grid_max2, memo, counts)
                    .unwrap_or_else(|| model.nearest_beyond_grid(&x, self.far)),
                None => model.nearest_any(&x, self.params.lookup, self.far),
            };
            all_d2 += d2;
            if d2 <= self.max2 {
                ne.add_rigid(&rz, &identity, &(x - m));
            }
        }
        (ne, all_d2)
    }
}

#[cfg(test)]
mod tests;
