//! Sensor attitude: the boresight (sensor `z`) looks at the target centre of
//! mass, sensor `y` ("down") leans towards a fixed LVLH reference direction,
//! and a small smooth pointing error keeps the target off dead centre.

use nalgebra::{Matrix3, Rotation3, Vector3};
use spacepose_geometry::so3;
use std::f64::consts::TAU;

/// `R_lvlh_sensor` whose `z` column is along `line_of_sight`, whose `y`
/// column is the part of `down_reference` orthogonal to it, and `x = y × z`
/// (sensor frame: `x` right, `y` down, `z` boresight). `down_reference` must
/// not be parallel to the line of sight (the trajectories ensure it).
pub fn look_at(line_of_sight: &Vector3<f64>, down_reference: &Vector3<f64>) -> Rotation3<f64> {
    look_at_with_rate(line_of_sight, &Vector3::zeros(), down_reference).0
}

/// [`look_at`] and its angular velocity in the sensor frame, given the rate
/// of change of the line of sight (fixed reference). With `z = u / |u|`,
/// `ż = (I − z zᵀ) u̇ / |u|`; with `n = r − (r·z) z`, `y = n / |n|`,
/// `ṅ = −(r·ż) z − (r·z) ż` and `ẏ = (I − y yᵀ) ṅ / |n|`. For `R = [x y z]`,
/// `Ṙ = R [ω]×` gives `ω = (ẏ·z, ż·x, −ẏ·x)`.
pub fn look_at_with_rate(
    line_of_sight: &Vector3<f64>,
    line_of_sight_rate: &Vector3<f64>,
    down_reference: &Vector3<f64>,
) -> (Rotation3<f64>, Vector3<f64>) {
    let range = line_of_sight.norm();
    let z = line_of_sight / range;
    let z_dot = (line_of_sight_rate - z * z.dot(line_of_sight_rate)) / range;
    let r = down_reference;
    let n = r - z * z.dot(r);
    let n_norm = n.norm();
    let y = n / n_norm;
    let n_dot = -z * r.dot(&z_dot) - z_dot * r.dot(&z);
    let y_dot = (n_dot - y * y.dot(&n_dot)) / n_norm;
    let x = y.cross(&z);
    let rotation = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x, y, z]));
    (
        rotation,
        Vector3::new(y_dot.dot(&z), z_dot.dot(&x), -y_dot.dot(&x)),
    )
}

/// Smooth pointing error: a rotation `Exp((e_x, e_y, 0))` applied in the
/// sensor frame, with `e_i(t) = A sin(2π t / P_i + φ_i)`. It runs on the
/// true clock (it is the attitude controller's, not the trajectory's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointingError {
    /// Amplitude `A` per axis (rad).
    pub amplitude: f64,
    /// Periods `P_x`, `P_y` (s).
    pub periods_s: [f64; 2],
    /// Phases `φ_x`, `φ_y` (rad).
    pub phases: [f64; 2],
}

impl PointingError {
    /// No error at all.
    pub fn none() -> Self {
        Self {
            amplitude: 0.0,
            periods_s: [1.0, 1.0],
            phases: [0.0, 0.0],
        }
    }

    /// The error rotation (sensor-nominal ← sensor) at `t`.
    pub fn rotation(&self, t: f64) -> Rotation3<f64> {
        self.rotation_and_rate(t).0
    }

    /// The error rotation `Exp(e)` and its angular velocity in the sensor
    /// frame, `J_r(e) ė` with the right Jacobian `J_r(e) = D_exp(−e)`.
    pub fn rotation_and_rate(&self, t: f64) -> (Rotation3<f64>, Vector3<f64>) {
        if self.amplitude == 0.0 {
            return (Rotation3::identity(), Vector3::zeros());
        }
        let arg = |i: usize| TAU * t / self.periods_s[i] + self.phases[i];
        let e = Vector3::new(arg(0).sin(), arg(1).sin(), 0.0) * self.amplitude;
        let e_dot = Vector3::new(
            arg(0).cos() * TAU / self.periods_s[0],
            arg(1).cos() * TAU / self.periods_s[1],
            0.0,
        ) * self.amplitude;
        (so3::exp(&e), so3::d_exp(&(-e)) * e_dot)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_builds_a_right_handed_frame_on_the_line_of_sight() {
        let los = Vector3::new(0.3, -15.0, 2.0);
        let r = look_at(&los, &Vector3::z());
        assert!((r * Vector3::z() - los.normalize()).norm() < 1e-15);
        assert!((r.matrix().determinant() - 1.0).abs() < 1e-12);
        assert!((r.matrix().transpose() * r.matrix() - Matrix3::identity()).norm() < 1e-12);
        // Sensor y leans towards the reference.
        assert!((r * Vector3::y()).dot(&Vector3::z()) > 0.9);
    }

    /// `Log(R(t−h)ᵀ R(t+h)) / 2h`.
    fn body_rate_fd(f: impl Fn(f64) -> Rotation3<f64>, t: f64, h: f64) -> Vector3<f64> {
        so3::log(&(f(t - h).inverse() * f(t + h))) / (2.0 * h)
    }

    #[test]
    fn look_at_rate_matches_finite_differences() {
        let u = |t: f64| Vector3::new(3.0 * t.sin(), -15.0 + t, 2.0 * (0.7 * t).cos());
        let u_dot = |t: f64| Vector3::new(3.0 * t.cos(), 1.0, -1.4 * (0.7 * t).sin());
        for t in [0.0, 0.4, 1.3, 2.9] {
            let (_, w) = look_at_with_rate(&u(t), &u_dot(t), &Vector3::z());
            let fd = body_rate_fd(|s| look_at(&u(s), &Vector3::z()), t, 1e-5);
            assert!((w - fd).norm() < 1e-8 * w.norm(), "{w:?} vs {fd:?}");
        }
    }

    #[test]
    fn pointing_error_rate_matches_finite_differences() {
        let err = PointingError {
            amplitude: 0.3,
            periods_s: [9.0, 13.0],
            phases: [0.2, 1.9],
        };
        for t in [0.0, 1.7, 5.2] {
            let (_, w) = err.rotation_and_rate(t);
            let fd = body_rate_fd(|s| err.rotation(s), t, 1e-5);
            assert!((w - fd).norm() < 1e-8 * w.norm(), "{w:?} vs {fd:?}");
        }
    }

    #[test]
    fn pointing_error_stays_within_its_amplitude() {
        let err = PointingError {
            amplitude: 0.3f64.to_radians(),
            periods_s: [97.0, 131.0],
            phases: [0.2, 1.9],
        };
        let mut worst: f64 = 0.0;
        for i in 0..2000 {
            let r = err.rotation(i as f64 * 0.37);
            worst = worst.max((r * Vector3::z()).angle(&Vector3::z()));
        }
        assert!(worst > 0.2f64.to_radians() && worst <= 0.3f64.to_radians() * 2f64.sqrt() + 1e-12);
    }
}
