//! The ICP iterations: correspondences through the [`IcpModel`] lookups
//! (with a nearest-neighbour memo per point), the closed-form Kabsch
//! update and the final evaluation.

use super::model::IcpModel;
use super::nearest_memo::{MemoCounts, NearestMemo};
use crate::error::RegistrationError;
use crate::normal_equations::NormalEquations;
use crate::params::{CellLookup, IcpParams};
use crate::result::{Cost, Increment, Registration};
use crate::source::{check_pose, finite_positions};
use nalgebra::{Matrix3, Rotation3, Vector3, Vector6};
use spacepose_geometry::{Point, Pose, so3};

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
        held_translations: 0,
        weakest_translation_cosine: f64::NAN,
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
