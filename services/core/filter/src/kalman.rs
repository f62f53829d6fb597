//! The Kalman update shared by both sub-filters, and the registration's
//! covariance from its information matrix.
//!
//! Both the position filter (state `[p; v]`) and the attitude IEKF (error
//! state `[ξ_R; ξ_ω; ξ_Ω]`) observe their first three states directly:
//! `H = [I₃ 0]`. This module implements that update once, with the
//! Joseph form `P⁺ = (I - K H) P (I - K H)ᵀ + K N Kᵀ`, which stays symmetric
//! positive definite for any gain, followed by an explicit symmetrisation.

use crate::error::FilterError;
use nalgebra::{Matrix3, Matrix6, SMatrix, SVector, Vector3};

/// A 3-D innovation (measurement residual) and its covariance
/// `S = H P Hᵀ + N`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Innovation {
    /// The residual `y` (rad for attitude, m for position).
    pub residual: Vector3<f64>,
    /// Its predicted covariance `S`.
    pub covariance: Matrix3<f64>,
}

impl Innovation {
    /// The innovation of an `N`-state filter with `H = [I₃ 0]`, covariance
    /// `P` and measurement noise `N`.
    pub fn new<const D: usize>(
        residual: Vector3<f64>,
        p: &SMatrix<f64, D, D>,
        n: &Matrix3<f64>,
    ) -> Self {
        let covariance = symmetrize(&(p.fixed_view::<3, 3>(0, 0) + n));
        Self {
            residual,
            covariance,
        }
    }

    /// The squared Mahalanobis distance `yᵀ S⁻¹ y`.
    pub fn mahalanobis2(&self) -> Result<f64, FilterError> {
        let chol = self
            .covariance
            .cholesky()
            .ok_or(FilterError::NotPositiveDefinite {
                what: "innovation covariance",
            })?;
        Ok(self.residual.dot(&chol.solve(&self.residual)))
    }
}

/// Correction `δx = K y` and posterior covariance of one update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct KalmanStep<const D: usize> {
    /// `δx = K y`.
    pub correction: SVector<f64, D>,
    /// Joseph-form posterior covariance.
    pub covariance: SMatrix<f64, D, D>,
}

/// One Kalman update with `H = [I₃ 0]`: `K = P Hᵀ S⁻¹`, `δx = K y`,
/// `P⁺ = (I - K H) P (I - K H)ᵀ + K N Kᵀ` (Joseph form).
pub(crate) fn update_first_block<const D: usize>(
    p: &SMatrix<f64, D, D>,
    innovation: &Innovation,
    n: &Matrix3<f64>,
) -> Result<KalmanStep<D>, FilterError> {
    let chol = innovation
        .covariance
        .cholesky()
        .ok_or(FilterError::NotPositiveDefinite {
            what: "innovation covariance",
        })?;
    let p_ht: SMatrix<f64, D, 3> = p.fixed_columns::<3>(0).into_owned();
    // S is symmetric, so K = P Hᵀ S⁻¹ = (S⁻¹ (P Hᵀ)ᵀ)ᵀ.
    let k: SMatrix<f64, D, 3> = chol.solve(&p_ht.transpose()).transpose();
    let mut h = SMatrix::<f64, 3, D>::zeros();
    h.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&Matrix3::identity());
    let i_kh = SMatrix::<f64, D, D>::identity() - k * h;
    let covariance = symmetrize(&(i_kh * p * i_kh.transpose() + k * n * k.transpose()));
    Ok(KalmanStep {
        correction: k * innovation.residual,
        covariance,
    })
}

/// The registration's covariance from its information matrix (6x6,
/// `δ = [rot; trans]`, left-⊕ of Eq. 5): `Σ = Λ⁻¹`. Fails when `Λ` is not
/// finite, symmetric and positive definite (e.g. a degenerate geometry).
pub fn covariance_from_information(
    information: &Matrix6<f64>,
) -> Result<Matrix6<f64>, FilterError> {
    let what = "registration information matrix";
    let chol = checked_symmetric(information, what)?
        .cholesky()
        .ok_or(FilterError::NotPositiveDefinite { what })?;
    let inv = symmetrize(&chol.inverse());
    if !inv.iter().all(|v| v.is_finite()) {
        return Err(FilterError::NotPositiveDefinite { what });
    }
    Ok(inv)
}

/// `(M + Mᵀ) / 2`.
pub(crate) fn symmetrize<const D: usize>(m: &SMatrix<f64, D, D>) -> SMatrix<f64, D, D> {
    (m + m.transpose()) * 0.5
}

/// Checks that a matrix is finite and symmetric (to a relative 1e-9);
/// returns its symmetrised copy.
fn checked_symmetric<const D: usize>(
    m: &SMatrix<f64, D, D>,
    what: &'static str,
) -> Result<SMatrix<f64, D, D>, FilterError> {
    if !m.iter().all(|v| v.is_finite()) {
        return Err(FilterError::NonFinite { what });
    }
    if (m - m.transpose()).abs().max() > 1e-9 * m.abs().max() {
        return Err(FilterError::NotPositiveDefinite { what });
    }
    Ok(symmetrize(m))
}

/// Checks that a covariance is finite, symmetric (to a relative 1e-9) and
/// positive definite; returns its symmetrised copy.
pub(crate) fn checked_covariance<const D: usize>(
    m: &SMatrix<f64, D, D>,
    what: &'static str,
) -> Result<SMatrix<f64, D, D>, FilterError> {
    let s = checked_symmetric(m, what)?;
    s.cholesky()
        .ok_or(FilterError::NotPositiveDefinite { what })?;
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joseph_update_matches_textbook_form_and_stays_pd() {
        let a = Matrix6::from_fn(|i, j| {
            ((i * 7 + j * 3) % 5) as f64 * 0.1 + if i == j { 1.0 } else { 0.0 }
        });
        let p = a * a.transpose();
        let n = Matrix3::from_diagonal(&Vector3::new(0.01, 0.02, 0.03));
        let y = Vector3::new(0.1, -0.2, 0.3);
        let inn = Innovation::new(y, &p, &n);
        let step = update_first_block(&p, &inn, &n).unwrap();
        // Textbook: P⁺ = P - K S Kᵀ, δx = P Hᵀ S⁻¹ y.
        let s_inv = inn.covariance.try_inverse().unwrap();
        let k = p.fixed_columns::<3>(0) * s_inv;
        let p_plus = p - k * inn.covariance * k.transpose();
        assert!((step.covariance - p_plus).abs().max() < 1e-10);
        assert!((step.correction - k * y).abs().max() < 1e-12);
        assert!(step.covariance.cholesky().is_some());
        assert_eq!(step.covariance, step.covariance.transpose());
    }

    #[test]
    fn rejects_bad_covariances() {
        let nan = Matrix3::from_element(f64::NAN);
        assert!(matches!(
            checked_covariance(&nan, "x"),
            Err(FilterError::NonFinite { .. })
        ));
        let neg = -Matrix3::<f64>::identity();
        assert!(checked_covariance(&neg, "x").is_err());
        let mut asym = Matrix3::<f64>::identity();
        asym[(0, 1)] = 0.5;
        assert!(checked_covariance(&asym, "x").is_err());
        assert!(checked_covariance(&Matrix3::identity(), "x").is_ok());
    }
}
