//! Decoding a label vector into an attitude: Γ_sym, seed 004 Algorithm 1.
//!
//! Take the class of largest weight `i_max`, keep the classes within Δβ of it
//! (d_sym, Eq. 14), replace each kept class by its symmetric equivalent closest
//! to `R_imax`, and project the weighted sum on SO(3) (Eq. 10: `Proj(M) = U Vᵀ`).

use nalgebra::{Matrix3, Rotation3};
use spacepose_geometry::so3;

use crate::classes::ClassTable;
use crate::error::CnnError;

/// Δβ of seed 004 §III.C.5 (deg): excludes the ±60° roll candidates of the hexagon.
pub const DEFAULT_DELTA_BETA_DEG: f64 = 50.0;

/// Γ_sym (Algorithm 1) with threshold `delta_beta_rad`.
///
/// # Errors
/// [`CnnError::LabelLength`] if `labels.len() != m`; [`CnnError::BadLabels`]
/// for NaN, infinite or negative weights, or weights summing to zero.
pub fn decode(
    classes: &ClassTable,
    labels: &[f32],
    delta_beta_rad: f64,
) -> Result<Rotation3<f64>, CnnError> {
    if labels.len() != classes.len() {
        return Err(CnnError::LabelLength {
            got: labels.len(),
            expected: classes.len(),
        });
    }
    if labels.iter().any(|v| !v.is_finite() || *v < 0.0) {
        return Err(CnnError::BadLabels("NaN, infinite or negative weight"));
    }
    let i_max = (0..labels.len())
        .max_by(|&a, &b| labels[a].total_cmp(&labels[b]))
        .ok_or(CnnError::BadLabels("empty"))?;
    if labels[i_max] <= 0.0 {
        return Err(CnnError::BadLabels("all weights are zero"));
    }
    Ok(decode_around(classes, labels, i_max, delta_beta_rad))
}

/// Algorithm 1 around class `i_max` instead of the most probable one (a
/// second mode of the label vector); `labels` must already be checked and
/// `i_max < m`.
pub(crate) fn decode_around(
    classes: &ClassTable,
    labels: &[f32],
    i_max: usize,
    delta_beta_rad: f64,
) -> Rotation3<f64> {
    let r_max = classes.rotations()[i_max];
    let syms = classes.symmetries();
    let mut sum = Matrix3::zeros();
    for (j, (r_j, &l_j)) in classes.rotations().iter().zip(labels).enumerate() {
        if l_j == 0.0 && j != i_max {
            continue;
        }
        // The symmetric equivalent R_j S_k closest to R_imax (k_j of Algorithm 1).
        let (d, r_jk) = syms
            .iter()
            .map(|s| {
                let r_jk = r_j * s;
                (so3::distance(&r_max, &r_jk), r_jk)
            })
            .fold((f64::INFINITY, *r_j), |a, b| if b.0 < a.0 { b } else { a });
        if d < delta_beta_rad {
            sum += r_jk.matrix() * f64::from(l_j);
        }
    }
    project_to_so3(&sum)
}

/// The `k` most probable modes of a checked label vector: class indices in
/// decreasing probability, each at least `delta_beta_rad` (d_sym, Eq. 14)
/// from the ones before, so that [`decode_around`] on each gives distinct
/// attitude hypotheses (the first is Algorithm 1's `i_max`).
pub(crate) fn modes(
    classes: &ClassTable,
    labels: &[f32],
    k: usize,
    delta_beta_rad: f64,
) -> Vec<usize> {
    let mut order: Vec<usize> = (0..labels.len()).collect();
    order.sort_by(|&a, &b| labels[b].total_cmp(&labels[a]));
    let rotations = classes.rotations();
    let mut chosen: Vec<usize> = Vec::with_capacity(k);
    for i in order {
        if chosen.len() == k || labels[i] <= 0.0 {
            break;
        }
        let far = chosen.iter().all(|&c| {
            so3::distance_sym(&rotations[c], &rotations[i], classes.symmetries()) >= delta_beta_rad
        });
        if far {
            chosen.push(i);
        }
    }
    chosen
}

/// Orthogonal projection on SO(3), `U Vᵀ` (Eq. 10), with the sign of the last
/// singular direction flipped if needed so the result is a rotation (det = +1).
pub fn project_to_so3(m: &Matrix3<f64>) -> Rotation3<f64> {
    let svd = m.svd(true, true);
    let (Some(mut u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Rotation3::identity();
    };
    if (u * v_t).determinant() < 0.0 {
        let mut col = u.column_mut(2);
        col *= -1.0;
    }
    Rotation3::from_matrix_unchecked(u * v_t)
}

#[cfg(test)]
#[path = "decode_tests.rs"]
mod tests;
