//! Reflection and beam maths of seed 004 §IV.A: the Phong model adapted to
//! lidar (Eq. 17), the reflection cone, and the Gaussian beam profile of the
//! divergence model (Eq. 18).

use nalgebra::Vector3;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use std::f64::consts::FRAC_PI_2;

/// The bracket of seed 004 Eq. (17): `k_d cos θ + (1 - k_d) cos^η α`,
/// the fraction of the incident intensity seen by an observer at angle `α`
/// from the mirror direction, for an incidence angle `θ`. Negative cosines
/// (observer behind the surface, or outside the specular half-space) give no
/// contribution. Multiply by `I_I / r²` for the received intensity.
#[inline]
pub fn phong(kd: f64, eta: f64, cos_theta: f64, cos_alpha: f64) -> f64 {
    let specular = if kd < 1.0 {
        (1.0 - kd) * cos_pow(cos_alpha, eta)
    } else {
        0.0
    };
    kd * cos_theta.max(0.0) + specular
}

/// `max(c, 0)^η`, skipping the `powf` when the result is 0.
#[inline]
pub fn cos_pow(c: f64, eta: f64) -> f64 {
    if c > 0.0 { c.powf(eta) } else { 0.0 }
}

/// Phong back-scatter toward a co-located emitter and receiver: Eq. (17)
/// with `α = 2θ`, so `cos α = 2 cos²θ - 1`.
#[inline]
pub fn phong_backscatter(kd: f64, eta: f64, cos_theta: f64) -> f64 {
    phong(kd, eta, cos_theta, 2.0 * cos_theta * cos_theta - 1.0)
}

/// Half-angle of the reflection cone `α_max = sqrt(2/η)` (seed 004: for
/// η ≫ 1 the specular lobe is `≈ 1 - η α²/2`), capped at 90°.
#[inline]
pub fn reflection_cone_half_angle(eta: f64) -> f64 {
    (2.0 / eta).sqrt().min(FRAC_PI_2)
}

/// Relative intensity of a ray diverging by `gamma` from the beam axis,
/// seed 004 Eq. (18): `exp(-2 γ² / β²)` (β: the 1/e² half-angle).
#[inline]
pub fn divergence_weight(gamma: f64, beta: f64) -> f64 {
    (-2.0 * gamma * gamma / (beta * beta)).exp()
}

/// Mirror direction of `d` on a surface of unit normal `n`.
#[inline]
pub fn mirror(d: &Vector3<f64>, n: &Vector3<f64>) -> Vector3<f64> {
    d - n * (2.0 * d.dot(n))
}

/// Two unit vectors completing `axis` (unit) into an orthonormal basis
/// (Duff et al. 2017, branchless).
#[inline]
pub fn orthonormal_basis(axis: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let sign = 1.0f64.copysign(axis.z);
    let a = -1.0 / (sign + axis.z);
    let b = axis.x * axis.y * a;
    (
        Vector3::new(1.0 + sign * axis.x * axis.x * a, sign * b, -sign * axis.x),
        Vector3::new(b, sign + axis.y * axis.y * a, -axis.y),
    )
}

/// `axis` (unit) tilted by `angle` toward the azimuth `azimuth` (rad).
#[inline]
pub fn tilt(axis: &Vector3<f64>, angle: f64, azimuth: f64) -> Vector3<f64> {
    let (u, v) = orthonormal_basis(axis);
    let (sa, ca) = angle.sin_cos();
    let (sp, cp) = azimuth.sin_cos();
    axis * ca + (u * cp + v * sp) * sa
}

/// A uniformly distributed unit vector of the plane, `(cos φ, sin φ)`, by
/// rejection from the unit square (cheaper than `sin_cos` of a uniform φ).
#[inline]
pub fn random_unit_circle(rng: &mut ChaCha8Rng) -> (f64, f64) {
    loop {
        let x: f64 = rng.random_range(-1.0..1.0);
        let y: f64 = rng.random_range(-1.0..1.0);
        let r2 = x * x + y * y;
        if r2 > 1e-12 && r2 <= 1.0 {
            let inv = 1.0 / r2.sqrt();
            return (x * inv, y * inv);
        }
    }
}

/// A cone of directions about one axis, with its orthonormal basis
/// precomputed (the divergent rays of one beam share it).
#[derive(Debug, Clone, Copy)]
pub struct Cone {
    axis: Vector3<f64>,
    u: Vector3<f64>,
    v: Vector3<f64>,
}

impl Cone {
    /// The cone about `axis` (unit).
    #[inline]
    pub fn new(axis: &Vector3<f64>) -> Self {
        let (u, v) = orthonormal_basis(axis);
        Cone { axis: *axis, u, v }
    }

    /// A direction at an angle uniform in `[0, max_angle]` from the axis, at
    /// a uniform azimuth; returns the direction and the angle.
    #[inline]
    pub fn sample(&self, max_angle: f64, rng: &mut ChaCha8Rng) -> (Vector3<f64>, f64) {
        let angle = rng.random_range(0.0..=max_angle);
        let (c, s) = random_unit_circle(rng);
        let (sa, ca) = angle.sin_cos();
        (self.axis * ca + (self.u * c + self.v * s) * sa, angle)
    }
}

/// A direction at an angle drawn uniformly in `[0, max_angle]` from `axis`,
/// at a uniform azimuth; returns the direction and the drawn angle.
/// Used for the divergent rays (γ ∈ [0, β], seed 004) and for the reflected
/// ray (α ∈ [0, sqrt(2/η)]).
#[inline]
pub fn sample_cone(
    axis: &Vector3<f64>,
    max_angle: f64,
    rng: &mut ChaCha8Rng,
) -> (Vector3<f64>, f64) {
    Cone::new(axis).sample(max_angle, rng)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn phong_reduces_to_lambert_for_a_diffuse_surface() {
        for c in [0.0, 0.3, 0.7, 1.0] {
            assert!((phong_backscatter(1.0, 3.0, c) - c).abs() < 1e-15);
        }
    }

    #[test]
    fn specular_backscatter_vanishes_off_normal() {
        // MLI-like: k_d = 1e-3, η = 50. Normal incidence returns everything,
        // 20° incidence (α = 40°) almost nothing.
        assert!((phong_backscatter(1e-3, 50.0, 1.0) - 1.0).abs() < 1e-12);
        let c20 = 20f64.to_radians().cos();
        assert!(phong_backscatter(1e-3, 50.0, c20) < 2e-3);
        // Beyond 45° the specular lobe is clamped, only the diffuse part stays.
        let c60 = 60f64.to_radians().cos();
        assert!((phong_backscatter(1e-3, 50.0, c60) - 1e-3 * c60).abs() < 1e-15);
    }

    #[test]
    fn reflection_cone_matches_the_lobe_approximation() {
        // cos^η α ≈ 1 - η α²/2 reaches 0 at α = sqrt(2/η).
        let eta = 50.0;
        let a = reflection_cone_half_angle(eta);
        assert!((1.0 - eta * a * a / 2.0).abs() < 1e-12);
        assert!((reflection_cone_half_angle(0.5) - FRAC_PI_2).abs() < 1e-15);
    }

    #[test]
    fn divergence_weight_is_one_over_e_squared_at_beta() {
        let beta = 0.28f64.to_radians();
        assert!((divergence_weight(0.0, beta) - 1.0).abs() < 1e-15);
        assert!((divergence_weight(beta, beta) - (-2.0f64).exp()).abs() < 1e-15);
    }

    #[test]
    fn mirror_and_cone_geometry() {
        let n = Vector3::new(0.0, 0.0, 1.0);
        let d = Vector3::new(1.0, 0.0, -1.0).normalize();
        let m = mirror(&d, &n);
        assert!((m - Vector3::new(1.0, 0.0, 1.0).normalize()).norm() < 1e-15);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for axis in [
            Vector3::z(),
            -Vector3::z(),
            Vector3::new(0.3, -0.5, 0.2).normalize(),
        ] {
            let (u, v) = orthonormal_basis(&axis);
            assert!(
                u.dot(&axis).abs() < 1e-12 && v.dot(&axis).abs() < 1e-12 && u.dot(&v).abs() < 1e-12
            );
            assert!((u.norm() - 1.0).abs() < 1e-12 && (v.norm() - 1.0).abs() < 1e-12);
            for _ in 0..100 {
                let (dir, angle) = sample_cone(&axis, 0.1, &mut rng);
                assert!((dir.norm() - 1.0).abs() < 1e-12);
                assert!((dir.angle(&axis) - angle).abs() < 1e-7);
                assert!(angle <= 0.1);
            }
        }
        // Uniform azimuth: the mean of (cos φ, sin φ) and of (cos 2φ, sin 2φ) vanish.
        let n = 20_000;
        let (mut c1, mut s1, mut c2, mut s2) = (0.0, 0.0, 0.0, 0.0);
        for _ in 0..n {
            let (c, s) = random_unit_circle(&mut rng);
            assert!((c * c + s * s - 1.0).abs() < 1e-12);
            c1 += c;
            s1 += s;
            c2 += c * c - s * s;
            s2 += 2.0 * c * s;
        }
        for m in [c1, s1, c2, s2] {
            assert!((m / n as f64).abs() < 0.02, "{m}");
        }
    }
}
