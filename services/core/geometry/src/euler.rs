//! 321 Euler angles (yaw ψ about z, then pitch θ about y, then roll φ about
//! x): `R = R_z(ψ) R_y(θ) R_x(φ)`, the convention of seed 002 §2 and seed 004
//! Eq. (5).

use nalgebra::{Rotation3, Vector3};
use serde::{Deserialize, Serialize};

/// Euler angles of the 321 (z-y-x) sequence, in radians.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Euler321 {
    /// Yaw ψ, rotation about z (rad).
    pub yaw: f64,
    /// Pitch θ, rotation about y (rad), in `[-π/2, π/2]`.
    pub pitch: f64,
    /// Roll φ, rotation about x (rad).
    pub roll: f64,
}

impl Euler321 {
    /// Angles in radians.
    pub fn new(yaw: f64, pitch: f64, roll: f64) -> Self {
        Self { yaw, pitch, roll }
    }

    /// Angles given in degrees.
    pub fn from_degrees(yaw_deg: f64, pitch_deg: f64, roll_deg: f64) -> Self {
        Self::new(
            yaw_deg.to_radians(),
            pitch_deg.to_radians(),
            roll_deg.to_radians(),
        )
    }

    /// `R = R_z(ψ) R_y(θ) R_x(φ)`.
    pub fn to_rotation(&self) -> Rotation3<f64> {
        Rotation3::from_axis_angle(&Vector3::z_axis(), self.yaw)
            * Rotation3::from_axis_angle(&Vector3::y_axis(), self.pitch)
            * Rotation3::from_axis_angle(&Vector3::x_axis(), self.roll)
    }

    /// The angles of a rotation, with pitch in `[-π/2, π/2]` and yaw, roll in
    /// `(-π, π]`. At gimbal lock (|pitch| = π/2) roll is set to zero.
    pub fn from_rotation(r: &Rotation3<f64>) -> Self {
        let m = r.matrix();
        let sp = (-m[(2, 0)]).clamp(-1.0, 1.0);
        let pitch = sp.asin();
        if sp.abs() > 1.0 - 1e-12 {
            // Only ψ ∓ φ is observable; put it all in yaw.
            let yaw = (-m[(0, 1)]).atan2(m[(1, 1)]);
            return Self::new(yaw, pitch, 0.0);
        }
        let yaw = m[(1, 0)].atan2(m[(0, 0)]);
        let roll = m[(2, 1)].atan2(m[(2, 2)]);
        Self::new(yaw, pitch, roll)
    }

    /// The angles in degrees as `[yaw, pitch, roll]`.
    pub fn to_degrees(&self) -> [f64; 3] {
        [
            self.yaw.to_degrees(),
            self.pitch.to_degrees(),
            self.roll.to_degrees(),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_away_from_gimbal_lock() {
        for &(y, p, r) in &[
            (10.0, 20.0, 30.0),
            (-170.0, -80.0, 179.0),
            (0.0, 0.0, 0.0),
            (95.0, 45.0, -135.0),
        ] {
            let e = Euler321::from_degrees(y, p, r);
            let back = Euler321::from_rotation(&e.to_rotation());
            let [yb, pb, rb] = back.to_degrees();
            assert!((yb - y).abs() < 1e-9 && (pb - p).abs() < 1e-9 && (rb - r).abs() < 1e-9);
        }
    }

    #[test]
    fn gimbal_lock_still_reproduces_the_rotation() {
        let e = Euler321::from_degrees(30.0, 90.0, 10.0);
        let r = e.to_rotation();
        let back = Euler321::from_rotation(&r).to_rotation();
        assert!((r.matrix() - back.matrix()).norm() < 1e-9);
    }

    #[test]
    fn sequence_is_yaw_then_pitch_then_roll() {
        // A pure yaw turns x into y.
        let r = Euler321::from_degrees(90.0, 0.0, 0.0).to_rotation();
        assert!((r * Vector3::x() - Vector3::y()).norm() < 1e-12);
    }
}
