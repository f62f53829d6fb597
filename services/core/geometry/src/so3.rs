//! SO(3): the exponential and logarithm maps and their derivatives.
//!
//! Conventions follow Sola et al. ("A micro Lie theory", seed 000 ref. 43)
//! and Eade ("Derivative of the exponential map", seed 000 ref. 46):
//! `Exp(ρ) = exp(ρ^×)` (seed 000 Eq. 4) and left perturbations
//! `Exp(τ) R`, which is the convention of the left ⊕ of Eq. (5).

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// Below this angle (rad) the closed forms switch to Taylor expansions.
const SMALL_ANGLE: f64 = 1e-5;

/// The cross-product (skew-symmetric) matrix `v^×`, with `v^× w = v × w`.
#[inline]
pub fn hat(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// The vector of a skew-symmetric matrix (inverse of [`hat`]).
#[inline]
pub fn vee(m: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(m[(2, 1)], m[(0, 2)], m[(1, 0)])
}

/// `Exp(ρ) = exp(ρ^×)` (seed 000 Eq. 4), by Rodrigues' formula.
pub fn exp(rho: &Vector3<f64>) -> Rotation3<f64> {
    let theta2 = rho.norm_squared();
    let theta = theta2.sqrt();
    let k = hat(rho);
    let (a, b) = if theta < SMALL_ANGLE {
        (1.0 - theta2 / 6.0, 0.5 - theta2 / 24.0)
    } else {
        (theta.sin() / theta, (1.0 - theta.cos()) / theta2)
    };
    Rotation3::from_matrix_unchecked(Matrix3::identity() + k * a + k * k * b)
}

/// `Log(R)`, the rotation vector of `R`, with angle in `[0, π]`.
///
/// Computed through the unit quaternion (Shepperd's method in nalgebra),
/// which stays accurate near 0 and near π where the trace formula does not.
pub fn log(r: &Rotation3<f64>) -> Vector3<f64> {
    let q = UnitQuaternion::from_rotation_matrix(r);
    log_quaternion(&q)
}

/// `Log` of a unit quaternion, with angle in `[0, π]`.
pub fn log_quaternion(q: &UnitQuaternion<f64>) -> Vector3<f64> {
    let (mut w, mut v) = (q.w, q.imag());
    if w < 0.0 {
        w = -w;
        v = -v;
    }
    let s = v.norm();
    if s < SMALL_ANGLE {
        // θ = 2 atan2(s, w) ≈ 2 s / w; Log = θ v / s ≈ 2 v / w (1 - s²/(3w²)).
        return v * (2.0 / w) * (1.0 - s * s / (3.0 * w * w));
    }
    let theta = 2.0 * s.atan2(w);
    v * (theta / s)
}

/// `D_exp(x)`, the left Jacobian of `Exp` (seed 000 Eq. A4):
/// `Exp(x + τ) ≈ Exp(D_exp(x) τ) Exp(x)` for small `τ`.
///
/// Closed form (Eade): `I + (1 - cos θ)/θ² x^× + (θ - sin θ)/θ³ (x^×)²`.
pub fn d_exp(x: &Vector3<f64>) -> Matrix3<f64> {
    let theta2 = x.norm_squared();
    let theta = theta2.sqrt();
    let k = hat(x);
    let (a, b) = if theta < SMALL_ANGLE {
        (0.5 - theta2 / 24.0, 1.0 / 6.0 - theta2 / 120.0)
    } else {
        (
            (1.0 - theta.cos()) / theta2,
            (theta - theta.sin()) / (theta2 * theta),
        )
    };
    Matrix3::identity() + k * a + k * k * b
}

/// `D_log(M)`, the derivative of `Log` under a left perturbation
/// (seed 000 Eq. A5): `Log(Exp(τ) M) ≈ Log(M) + D_log(M) τ`.
///
/// It is the inverse of the left Jacobian at `Log(M)` (Eade):
/// `I - ½ x^× + (1/θ² - (1 + cos θ) / (2 θ sin θ)) (x^×)²`.
/// Singular at θ = π, where `Log` itself is discontinuous.
pub fn d_log(m: &Rotation3<f64>) -> Matrix3<f64> {
    d_exp_inv(&log(m))
}

/// The inverse of [`d_exp`] at `x`, i.e. `D_log(Exp(x))` for `|x| < π`.
pub fn d_exp_inv(x: &Vector3<f64>) -> Matrix3<f64> {
    let theta2 = x.norm_squared();
    let theta = theta2.sqrt();
    let k = hat(x);
    let c = if theta < SMALL_ANGLE {
        1.0 / 12.0 + theta2 / 720.0
    } else {
        1.0 / theta2 - (1.0 + theta.cos()) / (2.0 * theta * theta.sin())
    };
    Matrix3::identity() - k * 0.5 + k * k * c
}

/// The angular distance `d(R, Q) = arccos((tr(Rᵀ Q) - 1) / 2)` (seed 004
/// Eq. 12), in radians, evaluated through `Log` for accuracy at small angles.
pub fn distance(r: &Rotation3<f64>, q: &Rotation3<f64>) -> f64 {
    log(&(r.transpose() * q)).norm()
}

/// The symmetric distance `d_sym(R, Q) = min_k d(R, Q^(k))` (seed 004 Eq. 14),
/// where `Q^(k) = Q S_k` for each symmetry `S_k` of the target (rotations of
/// the target body frame that leave its shape unchanged). An empty symmetry
/// list means the identity only.
pub fn distance_sym(r: &Rotation3<f64>, q: &Rotation3<f64>, symmetries: &[Rotation3<f64>]) -> f64 {
    if symmetries.is_empty() {
        return distance(r, q);
    }
    symmetries
        .iter()
        .map(|s| distance(r, &(q * s)))
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::f64::consts::PI;

    fn random_vector(rng: &mut ChaCha8Rng, scale: f64) -> Vector3<f64> {
        Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        ) * scale
    }

    fn rel_err(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
        (a - b).norm() / b.norm().max(1e-12)
    }

    #[test]
    fn exp_matches_nalgebra() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..100 {
            let v = random_vector(&mut rng, 3.0);
            let ours = exp(&v);
            let theirs = Rotation3::from_scaled_axis(v);
            assert!((ours.matrix() - theirs.matrix()).norm() < 1e-12);
        }
    }

    #[test]
    fn exp_log_round_trip_near_zero_and_near_pi() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        for &angle in &[
            0.0,
            1e-12,
            1e-8,
            1e-6,
            1e-3,
            0.5,
            2.0,
            PI - 1e-3,
            PI - 1e-6,
            PI - 1e-9,
        ] {
            for _ in 0..20 {
                let axis = random_vector(&mut rng, 1.0).normalize();
                let v = axis * angle;
                let back = log(&exp(&v));
                assert!(
                    (back - v).norm() < 1e-9 * (1.0 + angle),
                    "angle {angle}: {v:?} -> {back:?}"
                );
            }
        }
        // Exactly π: the axis is recovered up to sign.
        let v = Vector3::new(0.0, 0.0, PI);
        let back = log(&exp(&v));
        assert!((back.norm() - PI).abs() < 1e-12);
        assert!(back.normalize().dot(&v.normalize()).abs() > 1.0 - 1e-12);
    }

    #[test]
    fn d_exp_matches_finite_differences() {
        // D_exp(x) τ ≈ Log(Exp(x + τ) Exp(x)⁻¹), column by column (Eq. A4).
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let h = 1e-6;
        for &scale in &[1e-7, 0.1, 1.0, 2.5] {
            for _ in 0..10 {
                let x = random_vector(&mut rng, scale);
                let mut fd = Matrix3::zeros();
                for j in 0..3 {
                    let mut e = Vector3::zeros();
                    e[j] = h;
                    let plus = log(&(exp(&(x + e)) * exp(&x).inverse()));
                    let minus = log(&(exp(&(x - e)) * exp(&x).inverse()));
                    fd.set_column(j, &((plus - minus) / (2.0 * h)));
                }
                let err = rel_err(&d_exp(&x), &fd);
                assert!(err < 1e-6, "scale {scale}: rel err {err}");
            }
        }
    }

    #[test]
    fn d_log_matches_finite_differences() {
        // D_log(M) τ ≈ Log(Exp(τ) M) - Log(M) (Eq. A5).
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let h = 1e-6;
        for &scale in &[1e-7, 0.1, 1.0, 2.5] {
            for _ in 0..10 {
                let m = exp(&random_vector(&mut rng, scale));
                let mut fd = Matrix3::zeros();
                for j in 0..3 {
                    let mut e = Vector3::zeros();
                    e[j] = h;
                    let plus = log(&(exp(&e) * m));
                    let minus = log(&(exp(&(-e)) * m));
                    fd.set_column(j, &((plus - minus) / (2.0 * h)));
                }
                let err = rel_err(&d_log(&m), &fd);
                assert!(err < 1e-6, "scale {scale}: rel err {err}");
            }
        }
    }

    #[test]
    fn d_exp_inv_is_the_inverse() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..50 {
            let x = random_vector(&mut rng, 1.5);
            let prod = d_exp(&x) * d_exp_inv(&x);
            assert!((prod - Matrix3::identity()).norm() < 1e-12);
        }
    }

    #[test]
    fn distance_is_the_rotation_angle() {
        let r = exp(&Vector3::new(0.1, -0.2, 0.3));
        let q = exp(&Vector3::new(0.0, 0.0, 0.25)) * r;
        assert!((distance(&r, &q) - 0.25).abs() < 1e-12);
        assert!(distance(&r, &r) < 1e-12);
    }

    #[test]
    fn symmetric_distance_takes_the_closest_equivalent() {
        // A ±120° roll symmetry about the body x axis (seed 004 Fig. 5).
        let syms: Vec<_> = (0..3)
            .map(|k| exp(&Vector3::new(2.0 * PI / 3.0 * k as f64, 0.0, 0.0)))
            .collect();
        let truth = exp(&Vector3::new(0.3, 0.2, -0.1));
        let estimate = truth * syms[1] * exp(&Vector3::new(0.0, 0.02, 0.0));
        assert!(distance(&estimate, &truth) > 1.0);
        assert!((distance_sym(&estimate, &truth, &syms) - 0.02).abs() < 1e-9);
    }
}
