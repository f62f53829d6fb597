//! Per-cell normal distributions: mean, covariance, and the eigenvalue
//! floor that keeps planar (CAD) cells invertible.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

/// Mean and (population) covariance of `points[idx]`, `idx` in `indices`,
/// computed in two passes for accuracy. `indices` must not be empty.
pub(crate) fn mean_covariance(
    points: &[Vector3<f64>],
    indices: &[u32],
) -> (Vector3<f64>, Matrix3<f64>) {
    let n = indices.len().max(1) as f64;
    let mean = indices
        .iter()
        .fold(Vector3::zeros(), |acc, &i| acc + points[i as usize])
        / n;
    let mut cov = Matrix3::zeros();
    for &i in indices {
        let d = points[i as usize] - mean;
        cov += d * d.transpose();
    }
    (mean, cov / n)
}

/// Eigenvalue floor of a covariance: every eigenvalue is raised to
/// `max(λ, rel · λ_max, abs_sigma²)`.
///
/// A flat CAD face gives a cell with one zero eigenvalue (its normal) and a
/// straight edge gives two; the relative floor bounds the anisotropy of a
/// cell (1 % of the largest variance, i.e. a normal standard deviation of at
/// least 10 % of the in-plane one), the absolute one keeps tiny or
/// single-point cells from dominating the cost (2 mm by default). The
/// eigenvectors are kept, so a planar cell stays a flat ellipsoid with the
/// face normal as its thin axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct EigenFloor {
    /// Relative floor (fraction of the largest eigenvalue).
    pub rel: f64,
    /// Absolute floor on the standard deviation (m).
    pub abs_sigma: f64,
}

impl EigenFloor {
    /// The floored covariance and its inverse, or `None` if `cov` is not
    /// finite.
    pub(crate) fn apply(&self, cov: &Matrix3<f64>) -> Option<(Matrix3<f64>, Matrix3<f64>)> {
        if !cov.iter().all(|v| v.is_finite()) {
            return None;
        }
        let sym = (cov + cov.transpose()) * 0.5;
        let eig = SymmetricEigen::new(sym);
        let lambda_max = eig.eigenvalues.max().max(0.0);
        let floor = (self.rel * lambda_max).max(self.abs_sigma * self.abs_sigma);
        let lambda = eig.eigenvalues.map(|l| l.max(floor));
        let v = eig.eigenvectors;
        let floored = v * Matrix3::from_diagonal(&lambda) * v.transpose();
        let inverse = v * Matrix3::from_diagonal(&lambda.map(|l| 1.0 / l)) * v.transpose();
        // Exactly symmetric, so a stored map round-trips bit for bit.
        Some((
            (floored + floored.transpose()) * 0.5,
            (inverse + inverse.transpose()) * 0.5,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FLOOR: EigenFloor = EigenFloor {
        rel: 0.01,
        abs_sigma: 0.002,
    };

    fn planar_cell() -> Vec<Vector3<f64>> {
        // A 6 cm square of a tilted plane through (1, 2, 3), sampled on a 1 cm
        // grid: exactly planar, so its covariance has a zero eigenvalue.
        let n = Vector3::new(1.0, 1.0, 1.0).normalize();
        let a = n.cross(&Vector3::x()).normalize();
        let b = n.cross(&a);
        let mut pts = Vec::new();
        for i in 0..7 {
            for j in 0..7 {
                pts.push(
                    Vector3::new(1.0, 2.0, 3.0) + a * (i as f64 * 0.01) + b * (j as f64 * 0.01),
                );
            }
        }
        pts
    }

    #[test]
    fn planar_cell_is_regularised_along_its_normal() {
        let pts = planar_cell();
        let idx: Vec<u32> = (0..pts.len() as u32).collect();
        let (mean, cov) = mean_covariance(&pts, &idx);
        assert!((mean - (Vector3::new(1.0, 2.0, 3.0) + (pts[48] - pts[0]) * 0.5)).norm() < 1e-12);
        let normal = Vector3::new(1.0, 1.0, 1.0).normalize();
        // The raw covariance is singular along the normal…
        assert!((cov * normal).norm() < 1e-15);
        assert!(cov.determinant().abs() < 1e-20);
        let (floored, inverse) = FLOOR.apply(&cov).unwrap();
        // …the floored one is invertible, with the normal variance at the floor…
        let lambda_max = SymmetricEigen::new(cov).eigenvalues.max();
        let var_normal = normal.dot(&(floored * normal));
        let expected = (0.01 * lambda_max).max(0.002f64.powi(2));
        assert!((var_normal - expected).abs() < 1e-12 * expected.max(1.0));
        assert!(((floored * inverse) - Matrix3::identity()).norm() < 1e-9);
        // …and the in-plane variances are untouched.
        let a = normal.cross(&Vector3::x()).normalize();
        assert!((a.dot(&(floored * a)) - a.dot(&(cov * a))).abs() < 1e-12);
        // The inverse weights the normal direction most.
        assert!(normal.dot(&(inverse * normal)) > a.dot(&(inverse * a)) * 10.0);
    }

    #[test]
    fn single_point_cell_gets_the_absolute_floor() {
        let (floored, inverse) = FLOOR.apply(&Matrix3::zeros()).unwrap();
        assert!((floored - Matrix3::identity() * 4e-6).norm() < 1e-18);
        assert!((inverse - Matrix3::identity() / 4e-6).norm() < 1e-6);
    }

    #[test]
    fn non_finite_covariance_is_rejected() {
        let mut cov = Matrix3::identity();
        cov[(1, 2)] = f64::NAN;
        assert!(FLOOR.apply(&cov).is_none());
    }
}
