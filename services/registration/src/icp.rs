//! Point-to-point ICP (Besl & McKay; seed 000 §2.1, Table 1 ICP row) against
//! a kd-tree over the model cloud built once ([`IcpModel`]).
//!
//! Each iteration pairs every transformed point with its nearest model
//! point within `max_distance_m` and applies the closed-form optimal rigid
//! update for those pairs (Kabsch / Umeyama SVD, no scale); it stops when
//! the norm of the increment `[Log ΔR; Δp]` (left ⊕ of Eq. 5) drops below
//! `termination_increment`.

use crate::error::RegistrationError;
use crate::kdtree::{Tree3, build_tree};
use crate::normal_equations::NormalEquations;
use crate::params::IcpParams;
use crate::result::{Cost, Increment, Registration};
use crate::source::{check_pose, finite_positions};
use kiddo::SquaredEuclidean;
use nalgebra::{Matrix3, Rotation3, Vector3, Vector6};
use spacepose_geometry::{Point, Pose, so3};

/// The model cloud and its kd-tree, built once per target.
#[derive(Debug)]
pub struct IcpModel {
    points: Vec<Vector3<f64>>,
    tree: Tree3,
}

impl IcpModel {
    /// Builds the kd-tree over `model` (target body frame, m).
    ///
    /// Errors: fewer than 3 points, or a non-finite point.
    pub fn new(model: &[Vector3<f64>]) -> Result<Self, RegistrationError> {
        if model.len() < 3 {
            return Err(RegistrationError::InvalidModel(format!(
                "{} points, at least 3 needed",
                model.len()
            )));
        }
        if let Some(i) = model.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
            return Err(RegistrationError::InvalidModel(format!(
                "point {i} is not finite"
            )));
        }
        Ok(Self {
            points: model.to_vec(),
            tree: build_tree(model)?,
        })
    }

    /// Number of model points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True when the model has no point (never the case once built).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The nearest model point to `q` and the squared distance.
    #[inline]
    fn nearest(&self, q: &Vector3<f64>) -> (&Vector3<f64>, f64) {
        let hit = self
            .tree
            .query(&[q.x, q.y, q.z])
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        (&self.points[hit.item as usize], hit.distance)
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
    params.validate()?;
    check_pose("initial_t_target_sensor", initial_t_target_sensor)?;
    let (points, skipped) = finite_positions(source)?;
    let max2 = params.max_distance_m * params.max_distance_m;
    let no_match = |iteration| RegistrationError::NoCorrespondences {
        iteration,
        max_distance_m: params.max_distance_m,
    };
    let mut pose = *initial_t_target_sensor;
    let (mut converged, mut iterations, mut last) = (false, 0, Increment::default());
    for it in 0..params.max_iterations {
        let mut pairs = Pairs {
            x_sum: Vector3::zeros(),
            m_sum: Vector3::zeros(),
            cross: Matrix3::zeros(),
            count: 0,
        };
        for z in &points {
            let x = pose.transform(z);
            let (m, d2) = model.nearest(&x);
            if d2 <= max2 {
                pairs.x_sum += x;
                pairs.m_sum += m;
                pairs.cross += m * x.transpose();
                pairs.count += 1;
            }
        }
        if pairs.count == 0 {
            return Err(no_match(it));
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
    // Final evaluation at the returned pose.
    let mut ne = NormalEquations::new();
    let mut all_d2 = 0.0;
    let identity = Matrix3::identity();
    for z in &points {
        let rz = pose.rotation * z;
        let x = rz + pose.translation;
        let (m, d2) = model.nearest(&x);
        all_d2 += d2;
        if d2 <= max2 {
            ne.add_rigid(&rz, &identity, &(x - m));
        }
    }
    if ne.inliers == 0 {
        return Err(no_match(iterations));
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
    })
}

#[cfg(test)]
mod tests;
