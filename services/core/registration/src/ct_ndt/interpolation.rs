//! Pose interpolation within a scan (seed 000 Eq. 13) and its Jacobian
//! (Eq. 15, Appendix A.2), shared by the fixed- and free-start CT-NDT.

use crate::error::RegistrationError;
use nalgebra::{Matrix3, Matrix3x6, Vector3};
use spacepose_geometry::{Pose, so3};

/// Start and end times of a scan on the sensor clock (s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanTimes {
    /// `t^s`, time of the start pose.
    pub start_s: f64,
    /// `t^e`, time of the end pose (must be later than `start_s`).
    pub end_s: f64,
}

impl ScanTimes {
    /// Rejects non-finite times and an empty or reversed interval.
    pub fn validate(&self) -> Result<(), RegistrationError> {
        if self.start_s.is_finite() && self.end_s.is_finite() && self.end_s > self.start_s {
            Ok(())
        } else {
            Err(RegistrationError::param(
                "scan_times",
                format!(
                    "need finite start < end, got [{}, {}]",
                    self.start_s, self.end_s
                ),
            ))
        }
    }

    /// Interpolation factor `u = (t - t^s) / (t^e - t^s)` (Eq. 13).
    pub fn factor(&self, t_s: f64) -> f64 {
        (t_s - self.start_s) / (self.end_s - self.start_s)
    }
}

/// `interp(T^s, T^e, u)`: the pose of Eq. (13) at interpolation factor `u`,
/// for `T = t_target_sensor`. The attitude is the slerp of Eq. (13),
/// `R^u = Exp(u Log(R^e (R^s)⁻¹)) R^s`. The translation differs from the
/// paper's literal `(1-u) p^s + u p^e`: we interpolate linearly the target's
/// centre of mass in the sensor frame, `c = -Rᵀ p`, the constant-velocity
/// motion of Eq. (8), and set `p^u = -R^u c(u)`.
///
/// Why: `p` of `t_target_sensor` is the sensor origin seen from the target,
/// which moves on an arc of radius ‖c‖ while the target turns; the chord of
/// the literal formula is off by ‖c‖ (1 - cos(θ/2)) mid-scan, 5.7 cm at
/// 15 m for a 10° turn per scan, close to the 7.5 cm association distance.
/// The rotation part, and so Eq. (15)'s rotation block at `c = 0`, are
/// unchanged; the Jacobian gains the terms of [`ct_point_jacobian`].
/// `u` outside `[0, 1]` extrapolates at constant velocity.
pub fn interpolate(start: &Pose, end: &Pose, u: f64) -> Pose {
    let phi = so3::log(&(end.rotation * start.rotation.inverse()));
    let r_u = so3::exp(&(phi * u)) * start.rotation;
    let c_start = -(start.rotation.inverse() * start.translation);
    let c_end = -(end.rotation.inverse() * end.translation);
    let c_u = c_start * (1.0 - u) + c_end * u;
    Pose::new(r_u, -(r_u * c_u))
}

/// The coefficients `a = sin θ/θ`, `b = (1 - cos θ)/θ²`, `c = (θ - sin θ)/θ³`
/// of `Exp(x) = I + a x^× + b (x^×)²` and `D_exp(x) = I + b x^× + c (x^×)²`
/// (seed 000 Eq. 4 and A4), from `θ² = |x|²`. Below `θ = 0.2 rad` (11°,
/// every point of a 10°/s scan) by their Taylor series to `θ⁸`, whose
/// remainder is below 3e-15; above, with one `sin_cos` (it took 8 % of the
/// free-start CT-NDT's time).
#[inline]
pub(super) fn exp_coefficients(theta2: f64) -> (f64, f64, f64) {
    if theta2 < TAYLOR_THETA2 {
        let t = -theta2;
        // Σ t^k / (2k + 1)!, Σ t^k / (2k + 2)!, Σ t^k / (2k + 3)!, k ≤ 4.
        let a = 1.0 + t / 6.0 * (1.0 + t / 20.0 * (1.0 + t / 42.0 * (1.0 + t / 72.0)));
        let b = 0.5 * (1.0 + t / 12.0 * (1.0 + t / 30.0 * (1.0 + t / 56.0 * (1.0 + t / 90.0))));
        let c = (1.0 + t / 20.0 * (1.0 + t / 42.0 * (1.0 + t / 72.0 * (1.0 + t / 110.0)))) / 6.0;
        (a, b, c)
    } else {
        let theta = theta2.sqrt();
        let (s, co) = theta.sin_cos();
        (
            s / theta,
            (1.0 - co) / theta2,
            (theta - s) / (theta2 * theta),
        )
    }
}

/// `θ²` below which [`exp_coefficients`] uses the Taylor series.
const TAYLOR_THETA2: f64 = 0.04;

/// What every point shares within one linearisation at `T^e`.
pub(super) struct Interpolation {
    /// `R^s c^s = -p^s` and `R^s c^e`: the centre of mass at both ends,
    /// rotated by `R^s` (points are stored as `w = R^s z`).
    q_start: Vector3<f64>,
    q_end: Vector3<f64>,
    /// `φ = Log Q`, `Q = R^e (R^s)⁻¹`.
    pub(super) phi: Vector3<f64>,
    /// `φ^×` and `(φ^×)²`, for `R^u (R^e)ᵀ = Exp((u-1)φ)`.
    k1: Matrix3<f64>,
    k2: Matrix3<f64>,
    /// `(p^e)^×`, `φ^× (p^e)^×`, `(φ^×)² (p^e)^×`, for `Exp((u-1)φ) (p^e)^×`.
    p0: Matrix3<f64>,
    p1: Matrix3<f64>,
    p2: Matrix3<f64>,
    /// `(p^s)^×`, `φ^× (p^s)^×`, `(φ^×)² (p^s)^×`, for `Exp(uφ) (p^s)^×`
    /// in the start pose's Jacobian.
    s0: Matrix3<f64>,
    s1: Matrix3<f64>,
    s2: Matrix3<f64>,
    /// `D_log(Q)`, `φ^× D_log(Q)` and `(φ^×)² D_log(Q)`: with
    /// `D_exp(uφ) = I + b u φ^× + c u² (φ^×)²`, the product
    /// `D_exp(uφ) D_log(Q)` is a per-point combination of these three.
    l0: Matrix3<f64>,
    l1: Matrix3<f64>,
    l2: Matrix3<f64>,
}

/// Per point: the transformed point and the two Jacobian blocks.
pub(super) struct Linearised {
    pub(super) point: Vector3<f64>,
    pub(super) j_r: Matrix3<f64>,
    pub(super) j_t: Matrix3<f64>,
    /// The part of `j_r` from the rotation's interpolation (Eq. 15's
    /// rotation block), which the start pose's Jacobian reuses.
    pub(super) rot_block: Matrix3<f64>,
    /// `Exp((u-1)φ) = R^u (R^e)ᵀ` (`j_t = u` times it).
    pub(super) exp_v: Matrix3<f64>,
}

impl Interpolation {
    pub(super) fn new(start: &Pose, end: &Pose) -> Self {
        let phi = so3::log(&(end.rotation * start.rotation.inverse()));
        let k1 = so3::hat(&phi);
        let k2 = k1 * k1;
        let l0 = so3::d_exp_inv(&phi);
        let c_end = -(end.rotation.inverse() * end.translation);
        let p0 = so3::hat(&end.translation);
        let s0 = so3::hat(&start.translation);
        Self {
            q_start: -start.translation,
            q_end: start.rotation * c_end,
            phi,
            k1,
            k2,
            p0,
            p1: k1 * p0,
            p2: k2 * p0,
            s0,
            s1: k1 * s0,
            s2: k2 * s0,
            l0,
            l1: k1 * l0,
            l2: k2 * l0,
        }
    }

    /// The point `T_u(z) = R^u (z - c(u))` and its Jacobian for one point
    /// given `w = R^s z`, with `R^u y = Exp(uφ) R^s y` by Rodrigues on the
    /// vector.
    #[inline]
    pub(super) fn apply(&self, w: &Vector3<f64>, u: f64) -> Linearised {
        let phi2 = self.phi.norm_squared();
        let v = u - 1.0;
        self.apply_with(
            w,
            u,
            exp_coefficients(phi2 * u * u),
            exp_coefficients(phi2 * v * v),
        )
    }

    /// [`Interpolation::apply`] with the coefficients of
    /// [`exp_coefficients`] at `|φ|² u²` and `|φ|² (u-1)²` given (the
    /// free-start CT-NDT shares them between both ends, whose factors are
    /// `u` and `1 - u`).
    #[inline]
    pub(super) fn apply_with(
        &self,
        w: &Vector3<f64>,
        u: f64,
        (a, b, c): (f64, f64, f64),
        (a2, b2, _): (f64, f64, f64),
    ) -> Linearised {
        let x = self.phi * u;
        let y = w - (self.q_start * (1.0 - u) + self.q_end * u);
        let xy = x.cross(&y);
        let point = y + xy * a + x.cross(&xy) * b;
        let d = self.l0 + self.l1 * (b * u) + self.l2 * (c * u * u);
        // Exp((u-1)φ) = I + a' (u-1) φ^× + b' (u-1)² (φ^×)².
        let v = u - 1.0;
        let (s1, s2) = (a2 * v, b2 * v * v);
        let m = Matrix3::identity() + self.k1 * s1 + self.k2 * s2;
        let m_p = self.p0 + self.p1 * s1 + self.p2 * s2;
        let rot_block = Self::rotation_block(&point, &d, u);
        Linearised {
            point,
            j_r: rot_block + m_p * u,
            j_t: m * u,
            rot_block,
            exp_v: m,
        }
    }

    /// The Jacobian `[J_r, J_t]` of the same point for a left perturbation
    /// of the start pose, from the end pose's `end` (computed with the
    /// coefficients `(a, b, _)` at `|φ|² u²`). Perturbing both poses by one
    /// `δ` moves the interpolated pose by it, so `J^s = J^total − J^e` with
    /// `J^total = [-p^× + (1-u) Exp(uφ) (p^s)^× + u Exp((u-1)φ) (p^e)^×,
    /// (1-u) Exp(uφ) + u Exp((u-1)φ)]` (`p` the transformed point,
    /// `R^u (R^s)ᵀ = Exp(uφ)`), which leaves
    /// `J^s = [-p^× + (1-u) Exp(uφ) (p^s)^× - B, (1-u) Exp(uφ)]`, `B` Eq.
    /// (15)'s rotation block of the end. Cheaper than Eq. (15) with the
    /// ends swapped, which it equals.
    #[cfg(test)]
    pub(super) fn start_jacobian(
        &self,
        end: &Linearised,
        u: f64,
        coefficients: (f64, f64, f64),
    ) -> (Matrix3<f64>, Matrix3<f64>) {
        let (a, b, _) = coefficients;
        let exp_u = Matrix3::identity() + self.k1 * (a * u) + self.k2 * (b * u * u);
        (
            self.start_rotation_jacobian(end, u, coefficients),
            exp_u * (1.0 - u),
        )
    }

    /// The rotation block `J^s_r` of [`Interpolation::start_jacobian`]
    /// (the free-start CT-NDT forms the translation block from `exp_v`).
    #[inline]
    pub(super) fn start_rotation_jacobian(
        &self,
        end: &Linearised,
        u: f64,
        (a, b, _): (f64, f64, f64),
    ) -> Matrix3<f64> {
        let (c1, c2) = (a * u, b * u * u);
        let exp_u_ps = self.s0 + self.s1 * c1 + self.s2 * c2;
        exp_u_ps * (1.0 - u) - so3::hat(&end.point) - end.rot_block
    }

    /// `-(R^u y)^× u D_exp(u Log Q) D_log(Q)`, the rotation block of
    /// Eq. (15), column by column as cross products.
    #[inline]
    fn rotation_block(rz: &Vector3<f64>, d_exp_d_log: &Matrix3<f64>, u: f64) -> Matrix3<f64> {
        let m = d_exp_d_log * (-u);
        Matrix3::from_columns(&[
            rz.cross(&m.column(0)),
            rz.cross(&m.column(1)),
            rz.cross(&m.column(2)),
        ])
    }
}

/// The Jacobian `D interp(T^s, T^e, u)(z) / D T^e` for the left
/// perturbation `δ ⊕ T^e`, `δ = [rot; trans]`, of [`interpolate`]:
/// `[-(R^u y)^× u D_exp(u Log Q) D_log(Q) + u R^u (R^e)ᵀ (p^e)^×,
///   u R^u (R^e)ᵀ]` with `y = z - c(u)`. The first term is Eq. (15)'s
/// rotation block; the others come from the centre of mass interpolated in
/// the sensor frame (see [`interpolate`]). At `u = 1` it is Eq. (6).
pub fn ct_point_jacobian(start: &Pose, end: &Pose, u: f64, z: &Vector3<f64>) -> Matrix3x6<f64> {
    let l = Interpolation::new(start, end).apply(&(start.rotation * z), u);
    let mut j = Matrix3x6::zeros();
    j.fixed_view_mut::<3, 3>(0, 0).copy_from(&l.j_r);
    j.fixed_view_mut::<3, 3>(0, 3).copy_from(&l.j_t);
    j
}
