//! The joint normal equations of the free-start CT-NDT: the stacked
//! perturbation `[δ^s; δ^e]` of both scan-end poses, the data term of
//! every associated point (Eq. 13 with the Jacobian of Eq. 15 at both
//! ends), the Gaussian priors, and the solve.

use super::displacement_prior::DisplacementPrior;
use super::interpolation::{Interpolation, exp_coefficients};
use super::rate_prior::RatePrior;
use super::start_prior::StartPrior;
use crate::ndt_map::NdtMap;
use crate::params::NdtParams;
use nalgebra::{DMatrix, DVector, Matrix3, Matrix6, SMatrix, SVector, Vector3, Vector6};
use spacepose_geometry::{Pose, so3};

pub(super) type Matrix12 = SMatrix<f64, 12, 12>;
pub(super) type Vector12 = SVector<f64, 12>;
/// A point in the sensor frame with its interpolation factor `u` (Eq. 13).
pub(super) type TimedPoint = (Vector3<f64>, f64);

/// `Σ JᵀPJ`, `Σ JᵀPr`, `Σ rᵀPr`, `Σ |r|²` over the inliers for the stacked
/// perturbation `[δ^s; δ^e]`, with the Jacobian blocks
/// `[A_s, (1-u) M Q, A_e, u M]` (rotation and translation of each end;
/// `M = Exp((u-1)φ)`, `Q = Exp(φ) = R^e (R^s)ᵀ`, so that
/// `(1-u) Exp(uφ) = (1-u) M Q`).
///
/// The translation blocks share `M`, and the start's differs from the end's
/// by the per-scan `Q` and a scalar, so per point only `P M`, `P A_s`,
/// `P A_e` and six 3×3 products are formed (instead of four and ten for
/// general blocks); `Q` is applied once in [`Joint::assemble`].
pub(super) struct Joint {
    /// `Σ JᵀPJ` (12×12), plus the priors once added.
    pub(super) h: Matrix12,
    /// `Σ JᵀPr`, plus the priors once added.
    pub(super) g: Vector12,
    acc: Accumulators,
    /// `Σ rᵀPr` over the inliers.
    pub(super) cost: f64,
    /// `Σ |r|²` over the inliers (m²).
    pub(super) squared_distance: f64,
    /// Points associated with a cell.
    pub(super) inliers: usize,
}

/// The per-point sums behind [`Joint`] (names: `a` the rotation blocks,
/// `m` the translation factor `M`, `w = 1 - u`).
#[derive(Clone, Copy)]
struct Accumulators {
    a_s_a_s: Matrix3<f64>,
    a_s_a_e: Matrix3<f64>,
    a_e_a_e: Matrix3<f64>,
    /// `Σ w A_sᵀPM`, `Σ u A_sᵀPM`, `Σ w A_eᵀPM`, `Σ u A_eᵀPM`.
    a_s_m_w: Matrix3<f64>,
    a_s_m_u: Matrix3<f64>,
    a_e_m_w: Matrix3<f64>,
    a_e_m_u: Matrix3<f64>,
    /// `Σ w² MᵀPM`, `Σ wu MᵀPM`, `Σ u² MᵀPM`.
    m_m_ww: Matrix3<f64>,
    m_m_wu: Matrix3<f64>,
    m_m_uu: Matrix3<f64>,
    /// `Σ A_sᵀPr`, `Σ A_eᵀPr`, `Σ w MᵀPr`, `Σ u MᵀPr`.
    g_a_s: Vector3<f64>,
    g_a_e: Vector3<f64>,
    g_m_w: Vector3<f64>,
    g_m_u: Vector3<f64>,
}

impl Accumulators {
    fn zeros() -> Self {
        let (z, v) = (Matrix3::zeros(), Vector3::zeros());
        Self {
            a_s_a_s: z,
            a_s_a_e: z,
            a_e_a_e: z,
            a_s_m_w: z,
            a_s_m_u: z,
            a_e_m_w: z,
            a_e_m_u: z,
            m_m_ww: z,
            m_m_wu: z,
            m_m_uu: z,
            g_a_s: v,
            g_a_e: v,
            g_m_w: v,
            g_m_u: v,
        }
    }
}

impl Joint {
    pub(super) fn new() -> Self {
        Self {
            h: Matrix12::zeros(),
            g: Vector12::zeros(),
            acc: Accumulators::zeros(),
            cost: 0.0,
            squared_distance: 0.0,
            inliers: 0,
        }
    }

    /// Adds one residual `r` with information `p`, rotation blocks `a_s`,
    /// `a_e`, translation factor `m` and interpolation factor `u` (see
    /// [`Joint`]); [`Joint::assemble`] then fills `h` and `g`.
    #[allow(clippy::too_many_arguments)]
    fn add(
        &mut self,
        a_s: &Matrix3<f64>,
        a_e: &Matrix3<f64>,
        m: &Matrix3<f64>,
        u: f64,
        p: &Matrix3<f64>,
        r: &Vector3<f64>,
    ) {
        let w = 1.0 - u;
        let (p_a_s, p_a_e, p_m) = (p * a_s, p * a_e, p * m);
        let acc = &mut self.acc;
        acc.a_s_a_s += a_s.tr_mul(&p_a_s);
        acc.a_s_a_e += a_s.tr_mul(&p_a_e);
        acc.a_e_a_e += a_e.tr_mul(&p_a_e);
        let x_s = a_s.tr_mul(&p_m);
        let x_e = a_e.tr_mul(&p_m);
        let y = m.tr_mul(&p_m);
        acc.a_s_m_w += x_s * w;
        acc.a_s_m_u += x_s * u;
        acc.a_e_m_w += x_e * w;
        acc.a_e_m_u += x_e * u;
        acc.m_m_ww += y * (w * w);
        acc.m_m_wu += y * (w * u);
        acc.m_m_uu += y * (u * u);
        let pr = p * r;
        let m_pr = m.tr_mul(&pr);
        acc.g_a_s += a_s.tr_mul(&pr);
        acc.g_a_e += a_e.tr_mul(&pr);
        acc.g_m_w += m_pr * w;
        acc.g_m_u += m_pr * u;
        self.cost += r.dot(&pr);
        self.squared_distance += r.norm_squared();
        self.inliers += 1;
    }

    /// Adds the accumulated sums to `h` (both triangles) and `g`, with
    /// `q = R^e (R^s)ᵀ` (see [`Joint`]).
    fn assemble(&mut self, q: &Matrix3<f64>) {
        let a = std::mem::replace(&mut self.acc, Accumulators::zeros());
        let qt = q.transpose();
        // Upper block triangle, in the order [A_s, B_s, A_e, B_e].
        let upper = [
            (0, 0, a.a_s_a_s),
            (0, 1, a.a_s_m_w * q),
            (0, 2, a.a_s_a_e),
            (0, 3, a.a_s_m_u),
            (1, 1, qt * a.m_m_ww * q),
            (1, 2, qt * a.a_e_m_w.transpose()),
            (1, 3, qt * a.m_m_wu),
            (2, 2, a.a_e_a_e),
            (2, 3, a.a_e_m_u),
            (3, 3, a.m_m_uu),
        ];
        for (i, j, block) in upper {
            let mut view = self.h.fixed_view_mut::<3, 3>(3 * i, 3 * j);
            view += block;
            if j > i {
                let mut lower = self.h.fixed_view_mut::<3, 3>(3 * j, 3 * i);
                lower += block.transpose();
            }
        }
        for (i, block) in [a.g_a_s, qt * a.g_m_w, a.g_a_e, a.g_m_u]
            .into_iter()
            .enumerate()
        {
            let mut view = self.g.fixed_rows_mut::<3>(3 * i);
            view += block;
        }
    }

    /// Adds the prior `½ eᵀ Ω e` with `e = T^s ⊖ T^s₀`; `∂e/∂δ^s` is
    /// `blockdiag(J_l⁻¹(e_rot), I)` (left perturbation of `Log`).
    pub(super) fn add_prior(&mut self, start: &Pose, prior: &StartPrior) {
        let e = start.ominus(&prior.t_target_sensor);
        let mut jp = Matrix6::identity();
        let e_rot = Vector3::new(e[0], e[1], e[2]);
        jp.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&so3::d_exp_inv(&e_rot));
        let omega_jp = prior.information * jp;
        let h_ss = jp.tr_mul(&omega_jp);
        let g_s = jp.tr_mul(&(prior.information * e));
        let mut hv = self.h.fixed_view_mut::<6, 6>(0, 0);
        hv += h_ss;
        let mut gv = self.g.fixed_rows_mut::<6>(0);
        gv += g_s;
    }

    /// Adds the prior `eᵀ Ω e` of a [`RatePrior`] on the turn over the
    /// scan; it touches only the rotation blocks of both ends.
    pub(super) fn add_rate_prior(&mut self, start: &Pose, end: &Pose, rate: &RatePrior) {
        let r = rate.residual(&start.rotation, &end.rotation);
        let w = &rate.information;
        let blocks = [(0, r.j_start), (6, r.j_end)];
        for &(i, ji) in &blocks {
            let mut gv = self.g.fixed_rows_mut::<3>(i);
            gv += ji.tr_mul(&(w * r.e));
            for &(j, jj) in &blocks {
                let mut hv = self.h.fixed_view_mut::<3, 3>(i, j);
                hv += ji.tr_mul(&(w * jj));
            }
        }
    }

    /// Adds the prior `eᵀ Ω e` of a [`DisplacementPrior`]; it touches the
    /// rotation and translation blocks of both ends.
    pub(super) fn add_displacement_prior(
        &mut self,
        start: &Pose,
        end: &Pose,
        prior: &DisplacementPrior,
    ) {
        let r = prior.residual(start, end);
        let w = &prior.information;
        let blocks = [
            (0, r.j_start.0),
            (3, r.j_start.1),
            (6, r.j_end.0),
            (9, r.j_end.1),
        ];
        for &(i, ji) in &blocks {
            let mut gv = self.g.fixed_rows_mut::<3>(i);
            gv += ji.tr_mul(&(w * r.e));
            for &(j, jj) in &blocks {
                let mut hv = self.h.fixed_view_mut::<3, 3>(i, j);
                hv += ji.tr_mul(&(w * jj));
            }
        }
    }

    /// The information of `T^e` with `T^s` marginalised out.
    pub(super) fn end_information(&self) -> Matrix6<f64> {
        let h_ss = self.h.fixed_view::<6, 6>(0, 0).into_owned();
        let h_se = self.h.fixed_view::<6, 6>(0, 6).into_owned();
        let h_ee = self.h.fixed_view::<6, 6>(6, 6).into_owned();
        match h_ss.cholesky() {
            Some(c) => {
                let m = h_ee - h_se.transpose() * c.solve(&h_se);
                (m + m.transpose()) * 0.5
            }
            None => h_ee,
        }
    }

    /// Solves `H ε = -g` in `span(basis)` (all 12 directions when `None`).
    pub(super) fn solve(&self, basis: Option<&DMatrix<f64>>) -> Option<Vector12> {
        let eps = match basis {
            None => {
                let scale = self.h.diagonal().max();
                if !(scale.is_finite() && scale > 0.0) {
                    return None;
                }
                let chol = self.h.cholesky()?;
                let l = chol.l_dirty();
                if (0..12).any(|i| l[(i, i)] * l[(i, i)] <= 1e-12 * scale) {
                    return None;
                }
                -chol.solve(&self.g)
            }
            Some(q) => {
                let h = DMatrix::from_fn(12, 12, |i, j| self.h[(i, j)]);
                let g = DVector::from_fn(12, |i, _| self.g[i]);
                let y = (q.transpose() * &h * q)
                    .cholesky()?
                    .solve(&(q.transpose() * g));
                let eps = -(q * y);
                Vector12::from_iterator(eps.iter().copied())
            }
        };
        eps.iter().all(|v| v.is_finite()).then_some(eps)
    }
}

/// Normal equations at `(start, end)` over every point `z`
/// with interpolation factor `u`.
pub(super) fn linearise(
    map: &NdtMap,
    points: &[TimedPoint],
    start: &Pose,
    end: &Pose,
    params: &NdtParams,
) -> Joint {
    let forward = Interpolation::new(start, end);
    let mut joint = Joint::new();
    let phi2 = forward.phi.norm_squared();
    for &(z, u) in points {
        let c_u = exp_coefficients(phi2 * u * u);
        let c_v = exp_coefficients(phi2 * (1.0 - u) * (1.0 - u));
        let le = forward.apply_with(&(start.rotation * z), u, c_u, c_v);
        let Some((k, _)) = map.nearest_cell(&le.point, params.max_distance_m, params.lookup) else {
            continue;
        };
        let (mean, information) = map.mean_and_information(k);
        joint.add(
            &forward.start_rotation_jacobian(&le, u, c_u),
            &le.j_r,
            &le.exp_v,
            u,
            information,
            &(le.point - mean),
        );
    }
    joint.assemble(&(end.rotation * start.rotation.inverse()).into_inner());
    joint
}

pub(super) fn split(eps: &Vector12) -> (Vector6<f64>, Vector6<f64>) {
    (
        eps.fixed_rows::<6>(0).into_owned(),
        eps.fixed_rows::<6>(6).into_owned(),
    )
}
