//! Attitude classes (seed 004 §III.C.1 and §III.C.4): spiral sampling of the
//! sphere for yaw and pitch (Eqs. 6-7), a uniform roll step Δα, then the
//! removal of the classes made redundant by the target's symmetries.
//!
//! A class attitude is `R = Rz(ψ) Ry(θ) Rx(φ)` (Eq. 5), the rotation
//! `r_sensor_target` (target body → sensor). Symmetries `S` act on the right
//! (`R S`, as in `so3::distance_sym`), so a symmetry about the body `x` axis
//! (the roll axis of Eq. 5) shifts the roll: `Rz Ry Rx(φ) Rx(a) = Rz Ry Rx(φ + a)`.

use std::f64::consts::{PI, TAU};

use nalgebra::{Rotation3, UnitQuaternion, Vector3};
use spacepose_geometry::so3;
use spacepose_model::Target;

use crate::error::CnnError;

/// Default roll step Δα (deg), as chosen in seed 004 §V.B (Fig. 4 and 9).
pub const DEFAULT_ROLL_STEP_DEG: f64 = 20.0;

/// Number of points of the spiral, `n_s = ⌊4π / Δα²⌋` (Eq. 7, Δα in radians).
pub fn spiral_count(roll_step_rad: f64) -> usize {
    (4.0 * PI / (roll_step_rad * roll_step_rad)).floor() as usize
}

/// The spiral of Eq. (6): `n_s` (yaw ψ_k, pitch θ_k) pairs in radians, with
/// `z_k = (2k − (n_s − 1)) / n_s`, `ψ_k = √(n_s π) asin z_k` (wrapped to
/// [0, 2π)) and `θ_k = acos z_k − π/2`.
pub fn spiral(n_s: usize) -> Vec<(f64, f64)> {
    let n = n_s as f64;
    (0..n_s)
        .map(|k| {
            let z = (2.0 * k as f64 - (n - 1.0)) / n;
            let yaw = ((n * PI).sqrt() * z.asin()).rem_euclid(TAU);
            let pitch = z.acos() - 0.5 * PI;
            (yaw, pitch)
        })
        .collect()
}

/// The attitude classes `R_1..R_m` of a target, after symmetry reduction.
#[derive(Debug, Clone)]
pub struct ClassTable {
    roll_step_rad: f64,
    symmetries: Vec<Rotation3<f64>>,
    rotations: Vec<Rotation3<f64>>,
    full_count: usize,
}

impl ClassTable {
    /// The classes for roll step `roll_step_deg` and the symmetry group
    /// `symmetries` (identity first; empty = identity only).
    ///
    /// Reduction (§III.C.4): when every symmetry is a rotation about the body
    /// `x` axis by a multiple of `2π/k` (`k` = group order; `deos`:
    /// `{I, Rx(±120°)}`), the roll is restricted to `[0, 2π/k)`, which keeps
    /// exactly one of each set of symmetric classes when `Δα` divides `2π/k`
    /// (m = M/k). Any other group is reduced greedily: a class is dropped when
    /// it lies within Δα/2 (d_sym, Eq. 14) of a class already kept.
    ///
    /// # Errors
    /// [`CnnError::InvalidParameter`] for a roll step outside (0°, 90°];
    /// [`CnnError::Symmetry`] for a group whose first element is not the identity.
    pub fn new(roll_step_deg: f64, symmetries: &[Rotation3<f64>]) -> Result<Self, CnnError> {
        if !(roll_step_deg.is_finite() && roll_step_deg > 0.0 && roll_step_deg <= 90.0) {
            return Err(CnnError::InvalidParameter {
                name: "roll_step_deg",
                value: roll_step_deg,
            });
        }
        let symmetries = checked_group(symmetries)?;
        let step = roll_step_deg.to_radians();
        let roll_count = (TAU / step + 1e-9).floor() as usize;
        let roll_limit = match cyclic_order_about_x(&symmetries) {
            Some(k) => TAU / k as f64,
            None => TAU,
        };
        let mut full_count = 0;
        let mut rotations = Vec::new();
        for (yaw, pitch) in spiral(spiral_count(step)) {
            for j in 0..roll_count {
                full_count += 1;
                let roll = j as f64 * step;
                if roll < roll_limit - 1e-9 {
                    rotations.push(euler_zyx(yaw, pitch, roll));
                }
            }
        }
        if symmetries.len() > 1 && cyclic_order_about_x(&symmetries).is_none() {
            rotations = greedy_reduce(rotations, &symmetries, 0.5 * step);
        }
        Ok(ClassTable {
            roll_step_rad: step,
            symmetries,
            rotations,
            full_count,
        })
    }

    /// The classes of `target` (its declared symmetry group).
    ///
    /// # Errors
    /// As [`ClassTable::new`].
    pub fn for_target(target: &Target, roll_step_deg: f64) -> Result<Self, CnnError> {
        ClassTable::new(roll_step_deg, target.symmetries())
    }

    /// m, the number of classes after symmetry reduction.
    pub fn len(&self) -> usize {
        self.rotations.len()
    }

    /// Always false (a valid table has classes); for clippy's `len_without_is_empty`.
    pub fn is_empty(&self) -> bool {
        self.rotations.is_empty()
    }

    /// M, the number of classes before symmetry reduction (`n_s` × rolls).
    pub fn full_count(&self) -> usize {
        self.full_count
    }

    /// The class attitudes `R_i` (`r_sensor_target`).
    pub fn rotations(&self) -> &[Rotation3<f64>] {
        &self.rotations
    }

    /// The symmetry group used (identity first).
    pub fn symmetries(&self) -> &[Rotation3<f64>] {
        &self.symmetries
    }

    /// Δα (rad).
    pub fn roll_step_rad(&self) -> f64 {
        self.roll_step_rad
    }

    /// σ = 2Δα/3 of the soft labels (seed 004 §III.C.2: 3σ = 2Δα), in radians.
    pub fn sigma_rad(&self) -> f64 {
        2.0 * self.roll_step_rad / 3.0
    }

    /// The classes as unit quaternions (w, x, y, z), w ≥ 0, for `class_quaternions.npy`.
    pub fn quaternions_wxyz(&self) -> Vec<[f32; 4]> {
        self.rotations.iter().map(quaternion_wxyz).collect()
    }
}

/// `R = Rz(ψ) Ry(θ) Rx(φ)` (Eq. 5).
pub fn euler_zyx(yaw: f64, pitch: f64, roll: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Vector3::z_axis(), yaw)
        * Rotation3::from_axis_angle(&Vector3::y_axis(), pitch)
        * Rotation3::from_axis_angle(&Vector3::x_axis(), roll)
}

/// A rotation as an `f32` quaternion (w, x, y, z) with w ≥ 0.
pub fn quaternion_wxyz(r: &Rotation3<f64>) -> [f32; 4] {
    let q = UnitQuaternion::from_rotation_matrix(r);
    let s = if q.w < 0.0 { -1.0 } else { 1.0 };
    [
        (s * q.w) as f32,
        (s * q.i) as f32,
        (s * q.j) as f32,
        (s * q.k) as f32,
    ]
}

fn checked_group(symmetries: &[Rotation3<f64>]) -> Result<Vec<Rotation3<f64>>, CnnError> {
    let Some(first) = symmetries.first() else {
        return Ok(vec![Rotation3::identity()]);
    };
    if so3::distance(first, &Rotation3::identity()) > 1e-9 {
        return Err(CnnError::Symmetry(
            "the first symmetry must be the identity".into(),
        ));
    }
    if symmetries
        .iter()
        .any(|s| s.matrix().iter().any(|v| !v.is_finite()))
    {
        return Err(CnnError::Symmetry("non-finite symmetry".into()));
    }
    Ok(symmetries.to_vec())
}

/// `Some(k)` when the group is `{Rx(2πj/k), j = 0..k}`.
fn cyclic_order_about_x(symmetries: &[Rotation3<f64>]) -> Option<usize> {
    let k = symmetries.len();
    let about_x = |s: &Rotation3<f64>| {
        let v = so3::log(s);
        let angle = v.norm();
        if angle < 1e-9 {
            return true;
        }
        let on_axis = v.y.abs() < 1e-6 && v.z.abs() < 1e-6;
        let steps = angle * k as f64 / TAU;
        on_axis && (steps - steps.round()).abs() < 1e-6
    };
    symmetries.iter().all(about_x).then_some(k)
}

fn greedy_reduce(
    rotations: Vec<Rotation3<f64>>,
    symmetries: &[Rotation3<f64>],
    threshold: f64,
) -> Vec<Rotation3<f64>> {
    let mut kept: Vec<Rotation3<f64>> = Vec::new();
    for r in rotations {
        if kept
            .iter()
            .all(|q| so3::distance_sym(&r, q, symmetries) >= threshold)
        {
            kept.push(r);
        }
    }
    kept
}

#[cfg(test)]
#[path = "classes_tests.rs"]
mod tests;
