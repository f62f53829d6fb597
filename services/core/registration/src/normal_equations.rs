//! Accumulation and solution of the Gauss-Newton normal equations, seed 000
//! Eq. (7), for Jacobians of the form `J = [A  s·I₃]` (Eq. 6 and Eq. 15).

use crate::error::RegistrationError;
use crate::result::Increment;
use crate::weak_directions::{self, Held, WeakDirection};
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

/// `Σ JᵀPJ`, `Σ JᵀPr`, `Σ rᵀPr` and `Σ |r|²` over the inliers, kept as
/// 3×3 blocks so no 6×6 product is formed per point.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NormalEquations {
    h_rr: Matrix3<f64>,
    h_rt: Matrix3<f64>,
    h_tt: Matrix3<f64>,
    g_r: Vector3<f64>,
    g_t: Vector3<f64>,
    /// `Σ rᵀ P r`.
    pub cost: f64,
    /// `Σ |r|²`.
    pub squared_distance: f64,
    /// Number of terms added.
    pub inliers: usize,
}

impl NormalEquations {
    pub(crate) fn new() -> Self {
        Self {
            h_rr: Matrix3::zeros(),
            h_rt: Matrix3::zeros(),
            h_tt: Matrix3::zeros(),
            g_r: Vector3::zeros(),
            g_t: Vector3::zeros(),
            cost: 0.0,
            squared_distance: 0.0,
            inliers: 0,
        }
    }

    /// Accumulates one residual `r` with information `p` and the general
    /// Jacobian `[j_r  j_t]` (rotation and translation blocks).
    pub(crate) fn add_general(
        &mut self,
        j_r: &Matrix3<f64>,
        j_t: &Matrix3<f64>,
        p: &Matrix3<f64>,
        r: &Vector3<f64>,
    ) {
        let pr = p * r;
        let pjr = p * j_r;
        let pjt = p * j_t;
        self.h_rr += j_r.tr_mul(&pjr);
        self.h_rt += j_r.tr_mul(&pjt);
        self.h_tt += j_t.tr_mul(&pjt);
        self.g_r += j_r.tr_mul(&pr);
        self.g_t += j_t.tr_mul(&pr);
        self.cost += r.dot(&pr);
        self.squared_distance += r.norm_squared();
        self.inliers += 1;
    }

    /// Adds a rigid term, `J = [-(R z)^×  I₃]` (Eq. 6), with `rz = R z`.
    #[inline(always)]
    ///
    /// Uses the structure of `J`: with `A = -(R z)^×`, `AᵀP = [a × P_c]`
    /// column by column and `AᵀPA = [a × (AᵀP)ᵀ_c]`, so each block costs
    /// three cross products instead of a 3×3 product.
    pub(crate) fn add_rigid(&mut self, rz: &Vector3<f64>, p: &Matrix3<f64>, r: &Vector3<f64>) {
        let pr = p * r;
        // M = Aᵀ P = (R z)^× P, the top-right block.
        let m = Matrix3::from_columns(&[
            rz.cross(&p.column(0)),
            rz.cross(&p.column(1)),
            rz.cross(&p.column(2)),
        ]);
        // Aᵀ P A = (R z)^× Mᵀ.
        let mt = m.transpose();
        self.h_rr += Matrix3::from_columns(&[
            rz.cross(&mt.column(0)),
            rz.cross(&mt.column(1)),
            rz.cross(&mt.column(2)),
        ]);
        self.h_rt += m;
        self.h_tt += p;
        self.g_r += rz.cross(&pr);
        self.g_t += pr;
        self.cost += r.dot(&pr);
        self.squared_distance += r.norm_squared();
        self.inliers += 1;
    }

    /// `H = Σ JᵀPJ`, the information matrix in the `δ = [rot; trans]` order.
    pub(crate) fn hessian(&self) -> Matrix6<f64> {
        let mut h = Matrix6::zeros();
        h.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.h_rr);
        h.fixed_view_mut::<3, 3>(0, 3).copy_from(&self.h_rt);
        h.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&self.h_rt.transpose());
        h.fixed_view_mut::<3, 3>(3, 3).copy_from(&self.h_tt);
        h
    }

    /// Solves Eq. (7), `H ε = -g`, by Cholesky. Fails when `H` is not
    /// (numerically) positive definite: a pivot below `1e-12 · max Hᵢᵢ`.
    pub(crate) fn solve(&self, iteration: usize) -> Result<Vector6<f64>, RegistrationError> {
        let degenerate = RegistrationError::DegenerateSystem {
            iteration,
            inliers: self.inliers,
        };
        let h = self.hessian();
        let g = Vector6::new(
            self.g_r.x, self.g_r.y, self.g_r.z, self.g_t.x, self.g_t.y, self.g_t.z,
        );
        let scale = h.diagonal().max();
        if !(scale.is_finite() && scale > 0.0) {
            return Err(degenerate);
        }
        let chol = h.cholesky().ok_or(degenerate)?;
        let l = chol.l_dirty();
        if (0..6).any(|i| l[(i, i)] * l[(i, i)] <= 1e-12 * scale) {
            return Err(RegistrationError::DegenerateSystem {
                iteration,
                inliers: self.inliers,
            });
        }
        let eps = -chol.solve(&g);
        if eps.iter().all(|v| v.is_finite()) {
            Ok(eps)
        } else {
            Err(RegistrationError::DegenerateSystem {
                iteration,
                inliers: self.inliers,
            })
        }
    }
}

/// The well-constrained directions of a geometric information matrix
/// (see `NdtParams::min_lever_arm_m` and
/// `NdtParams::min_translation_cosine`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Constrained {
    /// Basis of the directions kept, in `δ = [rot; trans]` coordinates.
    pub basis: Vec<Vector6<f64>>,
    /// The weakest rotation's lever arm: `√(λ_min / N)` of the rotation
    /// block with the translation marginalised out (m).
    pub weakest_lever_arm_m: f64,
    /// The weakest translation's RMS cosine with the normals: `√(λ_min /
    /// N)` of the translation block with the kept rotations marginalised
    /// out (see [`crate::weak_directions`]).
    pub weakest_translation_cosine: f64,
    /// The directions left out: rotation axes, the rotations kept, and
    /// translation axes (weakest first).
    pub held: Held,
    /// The geometric information itself (unit point noise).
    pub information: Matrix6<f64>,
}

impl Constrained {
    /// From the geometric information `h = Σ Jᵀ n nᵀ J` of `n` points
    /// ([`crate::weak_directions`]): a rotation axis whose mean squared
    /// lever arm `λ / n` (translation free) is below `min_lever_arm_m²` is
    /// left out (a 1 rad turn about it moves the points along their
    /// normals by less than that, on average); then a translation whose
    /// `λ / n` (kept rotations free) is below `min_translation_cosine²`
    /// (a 1 m shift along it moves them by less than that many metres).
    /// `None` when the translation block is singular or `h` is not finite.
    pub(crate) fn of(
        h: &Matrix6<f64>,
        n: usize,
        min_lever_arm_m: f64,
        min_translation_cosine: f64,
    ) -> Option<Self> {
        if n == 0 || !h.iter().all(|v| v.is_finite()) {
            return None;
        }
        let rotations = weak_directions::rotations(h, n);
        if rotations.len() < 3 {
            return None;
        }
        let min2 = min_lever_arm_m * min_lever_arm_m;
        let held_rotations = rotations.iter().filter(|d| d.per_point < min2).count();
        let axes = |d: &[WeakDirection]| d.iter().map(|d| d.axis).collect::<Vec<_>>();
        let kept = axes(&rotations[held_rotations..]);
        let translations = weak_directions::translations(h, n, &kept);
        if translations.len() < 3 {
            return None;
        }
        let cos2 = min_translation_cosine * min_translation_cosine;
        let held_translations = translations.iter().filter(|d| d.per_point < cos2).count();
        let rot = |a: &Vector3<f64>| Vector6::new(a.x, a.y, a.z, 0.0, 0.0, 0.0);
        let trans = |a: &Vector3<f64>| Vector6::new(0.0, 0.0, 0.0, a.x, a.y, a.z);
        let basis: Vec<Vector6<f64>> = kept
            .iter()
            .map(rot)
            .chain(
                translations[held_translations..]
                    .iter()
                    .map(|d| trans(&d.axis)),
            )
            .collect();
        Some(Self {
            basis,
            weakest_lever_arm_m: rotations[0].per_point.sqrt(),
            weakest_translation_cosine: translations[0].per_point.sqrt(),
            held: Held {
                rotations: axes(&rotations[..held_rotations]),
                kept_rotations: kept,
                translations: axes(&translations[..held_translations]),
            },
            information: *h,
        })
    }

    /// Rotations left out.
    pub(crate) fn dropped(&self) -> usize {
        self.held.rotations.len()
    }

    /// Translations left out.
    pub(crate) fn held_translations(&self) -> usize {
        self.held.translations.len()
    }
}

impl NormalEquations {
    /// Solves Eq. (7) restricted to `span(basis)`: `ε = Q y` with
    /// `(Qᵀ H Q) y = -Qᵀ g`. The full basis gives [`NormalEquations::solve`].
    pub(crate) fn solve_in(
        &self,
        basis: &[Vector6<f64>],
        iteration: usize,
    ) -> Result<Vector6<f64>, RegistrationError> {
        if basis.len() == 6 {
            return self.solve(iteration);
        }
        let degenerate = RegistrationError::DegenerateSystem {
            iteration,
            inliers: self.inliers,
        };
        let k = basis.len();
        if k == 0 {
            return Err(degenerate);
        }
        let q = nalgebra::DMatrix::from_fn(6, k, |i, j| basis[j][i]);
        let h6 = self.hessian();
        let h = nalgebra::DMatrix::from_fn(6, 6, |i, j| h6[(i, j)]);
        let g = nalgebra::DVector::from_vec(vec![
            self.g_r.x, self.g_r.y, self.g_r.z, self.g_t.x, self.g_t.y, self.g_t.z,
        ]);
        let a = q.transpose() * &h * &q;
        let b = q.transpose() * g;
        let y = a.cholesky().ok_or(degenerate)?.solve(&b);
        let eps = -(q * y);
        let eps = Vector6::from_iterator(eps.iter().copied());
        if eps.iter().all(|v| v.is_finite()) {
            Ok(eps)
        } else {
            Err(RegistrationError::DegenerateSystem {
                iteration,
                inliers: self.inliers,
            })
        }
    }
}

/// Sizes of an increment `ε = [rot; trans]`.
pub(crate) fn increment_of(eps: &Vector6<f64>) -> Increment {
    Increment {
        rotation_rad: eps.fixed_rows::<3>(0).norm(),
        translation_m: eps.fixed_rows::<3>(3).norm(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix3x6;
    use spacepose_geometry::{Pose, so3};

    #[test]
    fn block_accumulation_matches_dense_products() {
        let t = Pose::new(
            so3::exp(&Vector3::new(0.3, -0.2, 0.9)),
            Vector3::new(1.0, 2.0, -3.0),
        );
        let z = Vector3::new(0.4, -1.3, 2.2);
        let p = Matrix3::new(4.0, 1.0, 0.5, 1.0, 3.0, -0.2, 0.5, -0.2, 2.0);
        let r = Vector3::new(0.01, -0.02, 0.03);
        let mut ne = NormalEquations::new();
        ne.add_rigid(&(t.rotation * z), &p, &r);
        let j: Matrix3x6<f64> = t.point_jacobian(&z);
        let h = j.transpose() * p * j;
        assert!((ne.hessian() - h).norm() < 1e-12);
        let g = j.transpose() * p * r;
        assert!((ne.g_r - g.fixed_rows::<3>(0)).norm() < 1e-14);
        assert!((ne.g_t - g.fixed_rows::<3>(3)).norm() < 1e-14);
        assert!((ne.cost - r.dot(&(p * r))).abs() < 1e-15);
    }

    #[test]
    fn rank_deficient_system_is_an_error() {
        let mut ne = NormalEquations::new();
        // A single point constrains only three directions.
        ne.add_rigid(
            &Vector3::new(1.0, 0.0, 0.0),
            &Matrix3::identity(),
            &Vector3::zeros(),
        );
        assert!(matches!(
            ne.solve(0),
            Err(RegistrationError::DegenerateSystem { .. })
        ));
    }
}
