//! Consistency of the published covariance (issue 25 item 5): the
//! normalised estimation error squared of each pose the tracker publishes,
//! NEES = δᵀ P⁻¹ δ with δ = estimate ⊖ truth (left rotation perturbation
//! about sensor axes, translation in the sensor frame: `Pose::ominus`, the
//! convention of `PoseEstimate::covariance`) and P that covariance. For a
//! consistent 6-dof estimate NEES follows χ²(6): mean 6, above 12.59 in 5 %
//! of frames and above 22.46 in 0.1 %. Truth only scores: this is computed
//! in the eval, never in the suite.

use nalgebra::{Matrix6, Rotation3};
use serde::Serialize;
use spacepose_geometry::{Pose, so3};

/// χ²(6) 95 % quantile.
pub const CHI2_6_95: f64 = 12.592;
/// χ²(6) 99.9 % quantile.
pub const CHI2_6_999: f64 = 22.458;

/// NEES of `estimate` with covariance `cov` (row major, `[rot (rad); trans
/// (m)]`) against `truth`, whose symmetric variant nearest the estimate is
/// used when `symmetries` is not empty. `None` when the covariance is
/// unknown (all zeros), not finite or not positive definite.
pub fn pose_nees(
    estimate: &Pose,
    cov: &[[f64; 6]; 6],
    truth: &Pose,
    symmetries: &[Rotation3<f64>],
) -> Option<f64> {
    let p = Matrix6::from_fn(|i, j| cov[i][j]);
    if p.iter().all(|v| *v == 0.0) || !p.iter().all(|v| v.is_finite()) {
        return None;
    }
    let nearest = symmetries
        .iter()
        .map(|s| truth.rotation * s)
        .min_by(|a, b| {
            so3::distance(&estimate.rotation, a).total_cmp(&so3::distance(&estimate.rotation, b))
        })
        .unwrap_or(truth.rotation);
    let truth = Pose {
        rotation: nearest,
        translation: truth.translation,
    };
    let delta = estimate.ominus(&truth);
    let chol = ((p + p.transpose()) * 0.5).cholesky()?;
    Some(delta.dot(&chol.solve(&delta)))
}

/// NEES over the frames with a pose and a known covariance.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct NeesSummary {
    /// Frames counted.
    pub frames: usize,
    /// Mean NEES (6 when consistent).
    pub mean: f64,
    /// Median NEES (5.35 when consistent).
    pub median: f64,
    /// Fraction of frames above [`CHI2_6_95`] (0.05 when consistent).
    pub above_95: f64,
    /// Fraction of frames above [`CHI2_6_999`] (0.001 when consistent).
    pub above_999: f64,
}

impl NeesSummary {
    /// The median, NaN when no frame was counted.
    pub fn median_or_nan(&self) -> f64 {
        if self.frames > 0 {
            self.median
        } else {
            f64::NAN
        }
    }

    /// The share above the 95 % bound, NaN when no frame was counted.
    pub fn above_95_or_nan(&self) -> f64 {
        if self.frames > 0 {
            self.above_95
        } else {
            f64::NAN
        }
    }

    /// The summary of `values` (non-finite ones skipped).
    pub fn of(values: impl IntoIterator<Item = f64>) -> Self {
        let mut v: Vec<f64> = values.into_iter().filter(|x| x.is_finite()).collect();
        if v.is_empty() {
            return Self::default();
        }
        v.sort_by(f64::total_cmp);
        let n = v.len() as f64;
        let above = |q: f64| v.iter().filter(|x| **x > q).count() as f64 / n;
        Self {
            frames: v.len(),
            mean: v.iter().sum::<f64>() / n,
            median: v[v.len() / 2],
            above_95: above(CHI2_6_95),
            above_999: above(CHI2_6_999),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector3, Vector6};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    fn diag(sigmas: [f64; 6]) -> [[f64; 6]; 6] {
        std::array::from_fn(|i| {
            std::array::from_fn(|j| if i == j { sigmas[i].powi(2) } else { 0.0 })
        })
    }

    /// Errors drawn from the stated covariance give NEES ~ χ²(6); errors
    /// 3 times larger give a mean near 54.
    #[test]
    fn errors_drawn_from_the_covariance_are_consistent() {
        let truth = Pose::new(
            Rotation3::from_euler_angles(0.3, -0.2, 1.0),
            Vector3::new(0.1, 0.2, 15.0),
        );
        let sigmas = [0.004, 0.002, 0.01, 0.01, 0.02, 0.005];
        let cov = diag(sigmas);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let draw = |rng: &mut ChaCha8Rng, k: f64| {
            let d = Vector6::from_fn(|i, _| {
                let z: f64 = StandardNormal.sample(rng);
                z * sigmas[i] * k
            });
            pose_nees(&truth.oplus(&d), &cov, &truth, &[]).unwrap()
        };
        let ok = NeesSummary::of((0..4000).map(|_| draw(&mut rng, 1.0)));
        assert!((ok.mean - 6.0).abs() < 0.3, "{ok:?}");
        assert!((ok.above_95 - 0.05).abs() < 0.015, "{ok:?}");
        let over = NeesSummary::of((0..4000).map(|_| draw(&mut rng, 3.0)));
        assert!((over.mean - 54.0).abs() < 4.0, "{over:?}");
    }

    #[test]
    fn the_nearest_symmetric_truth_is_used_and_unknown_covariance_is_none() {
        let truth = Pose::new(Rotation3::identity(), Vector3::new(0.0, 0.0, 10.0));
        let turn = Rotation3::from_axis_angle(&Vector3::z_axis(), 120f64.to_radians());
        let estimate = Pose::new(turn, truth.translation);
        let cov = diag([0.01; 6]);
        assert_eq!(
            pose_nees(&estimate, &cov, &truth, &[Rotation3::identity(), turn]),
            Some(0.0)
        );
        assert!(pose_nees(&estimate, &cov, &truth, &[]).unwrap() > 1e4);
        assert_eq!(pose_nees(&estimate, &[[0.0; 6]; 6], &truth, &[]), None);
        let mut bad = cov;
        bad[0][0] = f64::NAN;
        assert_eq!(pose_nees(&estimate, &bad, &truth, &[]), None);
        bad[0][0] = -1.0;
        assert_eq!(pose_nees(&estimate, &bad, &truth, &[]), None);
        assert_eq!(NeesSummary::of([f64::NAN]), NeesSummary::default());
    }
}
