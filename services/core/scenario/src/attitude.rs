//! Target attitude in inertial space: constant-rate spin, or the exact
//! closed-form torque-free motion of an axisymmetric rigid body.

use nalgebra::{Matrix3, Rotation3, Unit, UnitQuaternion, Vector3};
use spacepose_geometry::so3;
use std::f64::consts::PI;

/// Attitude model of the target: `attitude(t)` returns `R_inertial_body(t)`
/// and the body angular velocity ω (inertial rate, in the body frame).
#[derive(Debug, Clone, PartialEq)]
pub enum TargetAttitude {
    /// Rotation at a constant body rate: `R(t) = R₀ Exp(ω t)`. For a rate
    /// along a principal axis this is also torque-free motion.
    ConstantRate {
        /// `R_inertial_body` at `t = 0`.
        r0: Rotation3<f64>,
        /// Body angular velocity (rad/s).
        w_body: Vector3<f64>,
    },
    /// Torque-free axisymmetric body (Euler's equations, closed form).
    TorqueFree(AxisymmetricBody),
}

impl TargetAttitude {
    /// `R_inertial_body(t)` and the body angular velocity at `t`.
    pub fn at(&self, t: f64) -> (Rotation3<f64>, Vector3<f64>) {
        match self {
            TargetAttitude::ConstantRate { r0, w_body } => (r0 * so3::exp(&(w_body * t)), *w_body),
            TargetAttitude::TorqueFree(body) => body.at(t),
        }
    }
}

/// A torque-free rigid body with inertia `I_t (1 − a aᵀ) + I_a a aᵀ` (axial
/// moment `I_a` about the body unit vector `a`, transverse moment `I_t`).
///
/// Euler's equations `I ω̇ + ω × I ω = 0` give a constant axial rate `ω_a` and
/// a transverse rate turning about `a` in the body at `λ = (I_a − I_t) ω_a /
/// I_t`, so `ω(t) = Exp(λ t a) ω₀`. The attitude is then exactly
/// `R(t) = Exp(Ω_p t ĥ) R₀ Exp(−λ t a)`, with ĥ the (fixed) direction of the
/// angular momentum `H` and `Ω_p = |H| / I_t` the rate at which the symmetry
/// axis cones about `H`. Check: differentiating gives the body rate
/// `Ω_p Rᵀ ĥ − λ a = I ω / I_t − λ a` (as `Rᵀ ĥ = I ω / |H|`), whose axial
/// part is `(I_a / I_t − λ / ω_a) ω_a = ω_a` and transverse part `ω_⊥`.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisymmetricBody {
    /// Axial moment of inertia `I_a` (any unit; only ratios matter).
    pub i_axial: f64,
    /// Transverse moment of inertia `I_t`.
    pub i_transverse: f64,
    /// Symmetry (spin) axis in the body frame.
    pub axis: Unit<Vector3<f64>>,
    /// `R_inertial_body` at `t = 0`.
    pub r0: Rotation3<f64>,
    /// Body angular velocity at `t = 0` (rad/s).
    pub w0: Vector3<f64>,
}

impl AxisymmetricBody {
    /// A body spinning at `spin` (rad/s) about its symmetry axis `axis`, plus
    /// a transverse rate `transverse` (rad/s) along `transverse_dir` (made
    /// orthogonal to `axis`), oriented so that its angular momentum points
    /// along `h_inertial`, then turned by `phase` (rad) about that direction.
    #[allow(clippy::too_many_arguments)]
    pub fn with_momentum_along(
        i_axial: f64,
        i_transverse: f64,
        axis: Unit<Vector3<f64>>,
        transverse_dir: Vector3<f64>,
        spin: f64,
        transverse: f64,
        h_inertial: Unit<Vector3<f64>>,
        phase: f64,
    ) -> Self {
        let perp = transverse_dir - axis.into_inner() * axis.dot(&transverse_dir);
        let perp = perp
            .try_normalize(1e-12)
            .unwrap_or_else(|| any_orthogonal(&axis));
        let w0 = axis.into_inner() * spin + perp * transverse;
        let mut body = Self {
            i_axial,
            i_transverse,
            axis,
            r0: Rotation3::identity(),
            w0,
        };
        let h_body = body.inertia() * w0;
        let align = UnitQuaternion::rotation_between(&h_body, &h_inertial).unwrap_or_else(|| {
            UnitQuaternion::from_axis_angle(&Unit::new_normalize(any_orthogonal(&h_body)), PI)
        });
        body.r0 = so3::exp(&(h_inertial.into_inner() * phase)) * align.to_rotation_matrix();
        body
    }

    /// The inertia matrix in the body frame.
    pub fn inertia(&self) -> Matrix3<f64> {
        let a = self.axis.into_inner();
        Matrix3::identity() * self.i_transverse
            + a * a.transpose() * (self.i_axial - self.i_transverse)
    }

    /// Axial rate `ω_a` (rad/s).
    pub fn axial_rate(&self) -> f64 {
        self.axis.dot(&self.w0)
    }

    /// Magnitude of the transverse rate `|ω_⊥|` (rad/s).
    pub fn transverse_rate(&self) -> f64 {
        (self.w0 - self.axis.into_inner() * self.axial_rate()).norm()
    }

    /// `λ = (I_a − I_t) ω_a / I_t`: rate at which ω turns about the symmetry
    /// axis, seen from the body (rad/s).
    pub fn body_precession_rate(&self) -> f64 {
        (self.i_axial - self.i_transverse) * self.axial_rate() / self.i_transverse
    }

    /// `Ω_p = |H| / I_t`: rate at which the symmetry axis cones about the
    /// angular momentum in inertial space (rad/s).
    pub fn space_precession_rate(&self) -> f64 {
        (self.inertia() * self.w0).norm() / self.i_transverse
    }

    /// Nutation: the constant angle between the symmetry axis and `H`,
    /// `atan(I_t |ω_⊥| / (I_a ω_a))` (rad).
    pub fn nutation_angle(&self) -> f64 {
        (self.i_transverse * self.transverse_rate()).atan2(self.i_axial * self.axial_rate())
    }

    /// Unit angular momentum in inertial space (constant).
    pub fn momentum_direction(&self) -> Unit<Vector3<f64>> {
        Unit::new_normalize(self.r0 * (self.inertia() * self.w0))
    }

    /// Closed-form `R_inertial_body(t)` and body angular velocity `ω(t)`.
    pub fn at(&self, t: f64) -> (Rotation3<f64>, Vector3<f64>) {
        let lambda = self.body_precession_rate();
        let a = self.axis.into_inner();
        let h = self.momentum_direction().into_inner();
        let r = so3::exp(&(h * (self.space_precession_rate() * t)))
            * self.r0
            * so3::exp(&(a * (-lambda * t)));
        (r, so3::exp(&(a * (lambda * t))) * self.w0)
    }
}

fn any_orthogonal(v: &Vector3<f64>) -> Vector3<f64> {
    let helper = if v.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    v.cross(&helper).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Quaternion, Vector4};

    fn tumbling_body() -> AxisymmetricBody {
        AxisymmetricBody::with_momentum_along(
            1.2,
            1.0,
            Vector3::x_axis(),
            Vector3::y(),
            10f64.to_radians(),
            1f64.to_radians(),
            Unit::new_normalize(Vector3::new(0.0, 1.0, 0.1)),
            0.7,
        )
    }

    /// RK4 on (q, ω) with Euler's equations and q̇ = ½ q ⊗ (0, ω).
    fn integrate(body: &AxisymmetricBody, t_end: f64, h: f64) -> (Rotation3<f64>, Vector3<f64>) {
        let inertia = body.inertia();
        let inv = inertia.try_inverse().unwrap();
        let deriv = |q: &Vector4<f64>, w: &Vector3<f64>| {
            let qq = Quaternion::from(*q);
            let dq = qq * Quaternion::from_parts(0.0, *w) * 0.5;
            let dw = inv * (-w.cross(&(inertia * w)));
            (dq.coords, dw)
        };
        let mut q = UnitQuaternion::from_rotation_matrix(&body.r0)
            .into_inner()
            .coords;
        let mut w = body.w0;
        let steps = (t_end / h).round() as usize;
        for _ in 0..steps {
            let (k1q, k1w) = deriv(&q, &w);
            let (k2q, k2w) = deriv(&(q + k1q * (h / 2.0)), &(w + k1w * (h / 2.0)));
            let (k3q, k3w) = deriv(&(q + k2q * (h / 2.0)), &(w + k2w * (h / 2.0)));
            let (k4q, k4w) = deriv(&(q + k3q * h), &(w + k3w * h));
            q += (k1q + k2q * 2.0 + k3q * 2.0 + k4q) * (h / 6.0);
            w += (k1w + k2w * 2.0 + k3w * 2.0 + k4w) * (h / 6.0);
            q.normalize_mut();
        }
        (
            UnitQuaternion::from_quaternion(Quaternion::from(q)).to_rotation_matrix(),
            w,
        )
    }

    #[test]
    fn closed_form_matches_rk4_integration_of_euler_equations() {
        let body = tumbling_body();
        let t_end = 47.3;
        let (r_rk4, w_rk4) = integrate(&body, t_end, 1e-3);
        let (r, w) = body.at(t_end);
        assert!(
            so3::distance(&r, &r_rk4) < 1e-9,
            "{}",
            so3::distance(&r, &r_rk4)
        );
        assert!((w - w_rk4).norm() < 1e-12);
    }

    #[test]
    fn momentum_and_energy_are_conserved() {
        let body = tumbling_body();
        let inertia = body.inertia();
        let (r0, w0) = body.at(0.0);
        let h0 = r0 * (inertia * w0);
        let e0 = 0.5 * w0.dot(&(inertia * w0));
        for i in 0..400 {
            let t = 3.7 * i as f64;
            let (r, w) = body.at(t);
            let h = r * (inertia * w);
            let e = 0.5 * w.dot(&(inertia * w));
            assert!(
                (h - h0).norm() < 1e-12 * h0.norm(),
                "t={t}: {h:?} vs {h0:?}"
            );
            assert!((e - e0).abs() < 1e-13 * e0);
        }
    }

    #[test]
    fn axis_cones_about_momentum_at_the_nutation_angle() {
        let body = tumbling_body();
        let h = body.momentum_direction();
        let expected = body.nutation_angle();
        assert!((expected.to_degrees() - (1.0f64 / 12.0).atan().to_degrees()).abs() < 1e-12);
        for i in 0..50 {
            let (r, _) = body.at(i as f64 * 1.3);
            let angle = (r * body.axis.into_inner()).angle(&h);
            assert!((angle - expected).abs() < 1e-12);
        }
        // Cone period 2π / Ω_p: the axis comes back.
        let period = std::f64::consts::TAU / body.space_precession_rate();
        let a0 = body.at(0.0).0 * body.axis.into_inner();
        let a1 = body.at(period).0 * body.axis.into_inner();
        assert!((a0 - a1).norm() < 1e-12);
    }

    #[test]
    fn constant_rate_turns_at_its_rate() {
        let w = Vector3::new(0.01, -0.02, 0.015);
        let model = TargetAttitude::ConstantRate {
            r0: so3::exp(&Vector3::new(0.3, 0.2, -1.0)),
            w_body: w,
        };
        let (r0, _) = model.at(10.0);
        let (r1, w1) = model.at(12.0);
        assert!((so3::log(&(r0.inverse() * r1)) - w * 2.0).norm() < 1e-12);
        assert_eq!(w1, w);
    }
}
