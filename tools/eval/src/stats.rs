//! Summary statistics for evaluation tables and JSON reports.

use serde::Serialize;

/// Mean and maximum of a series, the two columns the papers report.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MeanMax {
    /// Arithmetic mean (NaN for an empty series).
    pub mean: f64,
    /// Maximum (NaN for an empty series).
    pub max: f64,
}

impl Default for MeanMax {
    /// The figures of an empty series (NaN).
    fn default() -> Self {
        Self::of(&[])
    }
}

impl MeanMax {
    /// Mean and max of the finite values of `values`; NaN when none is finite.
    pub fn of(values: &[f64]) -> Self {
        let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
        if finite.is_empty() {
            return Self {
                mean: f64::NAN,
                max: f64::NAN,
            };
        }
        let mean = finite.iter().sum::<f64>() / finite.len() as f64;
        let max = finite.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Self { mean, max }
    }
}

/// The median of the finite values (NaN when none is finite).
pub fn median(values: &[f64]) -> f64 {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_max_ignores_non_finite_values() {
        let m = MeanMax::of(&[1.0, 3.0, f64::NAN, 2.0]);
        assert_eq!(m.mean, 2.0);
        assert_eq!(m.max, 3.0);
        assert!(MeanMax::of(&[]).mean.is_nan());
    }

    #[test]
    fn median_of_even_and_odd_series() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    }
}
