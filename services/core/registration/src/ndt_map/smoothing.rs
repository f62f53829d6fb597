//! The Gaussian smoothing of the NDT cells, seed 000 Eq. (1)-(2).

use crate::error::RegistrationError;
use crate::kdtree::build_tree;
use kiddo::SquaredEuclidean;
use nalgebra::{Matrix3, Vector3};

/// A cell's distribution before smoothing.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RawCell {
    /// Mean of the cell's points.
    pub mean: Vector3<f64>,
    /// Covariance of the cell's points (already floored).
    pub covariance: Matrix3<f64>,
    /// Number of model points in the cell (`n_k` of Eq. 2).
    pub count: u32,
    /// Centre `c` of the cell (Eq. 2).
    pub centre: Vector3<f64>,
}

/// A mean and a covariance.
pub(crate) type Gaussian = (Vector3<f64>, Matrix3<f64>);

/// Smooths every cell: cell `k` is replaced by the aggregate (Eq. 1) of all
/// cells whose mean lies within `radius` of its centre `c_k`, with weights
/// `w ∝ n exp(-|μ - c_k|² / 2σ²)` (Eq. 2), normalised to sum to one.
///
/// Eq. (1) is evaluated with means taken relative to `c_k`, which is
/// algebraically identical and avoids cancellation far from the origin.
/// A cell with no mean within the radius of its own centre (possible only
/// for a sparse, elongated leaf) keeps its own distribution.
pub(crate) fn smooth(
    cells: &[RawCell],
    sigma: f64,
    radius: f64,
) -> Result<Vec<Gaussian>, RegistrationError> {
    let means: Vec<Vector3<f64>> = cells.iter().map(|c| c.mean).collect();
    let tree = build_tree(&means)?;
    let inv_two_sigma2 = 1.0 / (2.0 * sigma * sigma);
    let radius2 = radius * radius;
    let mut out = Vec::with_capacity(cells.len());
    let mut neighbours: Vec<(u32, f64)> = Vec::new();
    for cell in cells {
        let c = cell.centre;
        neighbours.clear();
        tree.query(&[c.x, c.y, c.z])
            .within::<SquaredEuclidean<f64>>(radius2)
            .unsorted()
            .visit(|hit| neighbours.push((hit.item, hit.distance)));
        let mut w_sum = 0.0;
        let mut d_mean = Vector3::zeros();
        let mut second = Matrix3::zeros();
        for &(k, dist2) in &neighbours {
            let other = &cells[k as usize];
            let w = f64::from(other.count) * (-dist2 * inv_two_sigma2).exp(); // Eq. (2)
            let d = other.mean - c;
            w_sum += w;
            d_mean += d * w;
            second += (other.covariance + d * d.transpose()) * w;
        }
        if w_sum <= 0.0 || !w_sum.is_finite() {
            out.push((cell.mean, cell.covariance));
            continue;
        }
        // Eq. (1) with normalised weights, relative to c.
        let d_mean = d_mean / w_sum;
        let cov = second / w_sum - d_mean * d_mean.transpose();
        out.push((c + d_mean, cov));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cell(x: f64, count: u32, var: f64) -> RawCell {
        let mean = Vector3::new(x, 0.0, 0.0);
        RawCell {
            mean,
            covariance: Matrix3::identity() * var,
            count,
            centre: mean,
        }
    }

    #[test]
    fn eq_1_and_2_on_two_cells() {
        let sigma = 0.1;
        let cells = [
            cell(0.0, 10, 1e-4),
            cell(0.1, 30, 4e-4),
            cell(5.0, 10, 1e-4),
        ];
        let out = smooth(&cells, sigma, 0.3).unwrap();
        // Cell 0 aggregates cells 0 and 1 (cell 2 is far outside 3σ).
        let w0 = 10.0;
        let w1 = 30.0 * (-0.01f64 / (2.0 * 0.01)).exp();
        let (a, b) = (w0 / (w0 + w1), w1 / (w0 + w1));
        let mu = b * 0.1;
        assert!((out[0].0.x - mu).abs() < 1e-15);
        let var_x = a * 1e-4 + b * (4e-4 + 0.01) - mu * mu;
        let var_y = a * 1e-4 + b * 4e-4;
        assert!((out[0].1[(0, 0)] - var_x).abs() < 1e-15);
        assert!((out[0].1[(1, 1)] - var_y).abs() < 1e-15);
        // The isolated cell is unchanged.
        assert!((out[2].0 - cells[2].mean).norm() < 1e-15);
        assert!((out[2].1 - cells[2].covariance).norm() < 1e-15);
    }
}
