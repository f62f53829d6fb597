//! Centroids of point sets: the plain mean and the trimmed centroid of
//! seed 004 §III.A.1, Eqs. (1)-(2), which is robust to ghost reflections.
//!
//! Both work on any slice whose items expose a position through
//! [`HasPosition`] (implemented for [`Point`] and `Vector3<f64>`), so the
//! tracker, template matching and the CNN pre-processing share them.

use nalgebra::Vector3;

use crate::error::GeometryError;
use crate::point::Point;

/// The trimming factor chosen in seed 004 (§III.A.1): 25 % (interquartile mean).
pub const DEFAULT_TRIM: f64 = 0.25;

/// Anything with a 3D position in metres.
pub trait HasPosition {
    /// The position, in double precision.
    fn position_m(&self) -> Vector3<f64>;
}

impl HasPosition for Point {
    #[inline]
    fn position_m(&self) -> Vector3<f64> {
        self.position()
    }
}

impl HasPosition for Vector3<f64> {
    #[inline]
    fn position_m(&self) -> Vector3<f64> {
        *self
    }
}

/// The mean position of `points`.
///
/// Returns `None` when there is no finite mean: the slice is empty or some
/// position has a NaN or infinite coordinate (intensity and time are ignored).
pub fn centroid<P: HasPosition>(points: &[P]) -> Option<Vector3<f64>> {
    if points.is_empty() {
        return None;
    }
    let sum = points
        .iter()
        .fold(Vector3::zeros(), |acc, p| acc + p.position_m());
    let mean = sum / points.len() as f64;
    mean.iter().all(|c| c.is_finite()).then_some(mean)
}

/// The trimmed centroid of seed 004 Eqs. (1)-(2): along each axis
/// independently, discard the `floor(trim · N)` lowest and as many highest
/// coordinates and average the rest. `trim = 0.25` ([`DEFAULT_TRIM`]) gives
/// the paper's `c = 2/N Σ_{i=N/4+1}^{3N/4} (x_σx(i), y_σy(i), z_σz(i))`;
/// `trim = 0` is the plain mean.
///
/// Uses O(N) partial selection per axis, not a full sort; allocates one
/// scratch buffer of N `f64` (see [`trimmed_centroid_with_scratch`] to reuse it).
///
/// # Errors
/// [`GeometryError::InvalidTrim`] unless `0 <= trim < 0.5`;
/// [`GeometryError::EmptyInput`] for an empty slice;
/// [`GeometryError::NonFinitePosition`] if a coordinate is NaN or infinite.
pub fn trimmed_centroid<P: HasPosition>(
    points: &[P],
    trim: f64,
) -> Result<Vector3<f64>, GeometryError> {
    trimmed_centroid_with_scratch(points, trim, &mut Vec::new())
}

/// [`trimmed_centroid`] with a caller-owned scratch buffer, for hot loops.
///
/// # Errors
/// As [`trimmed_centroid`].
pub fn trimmed_centroid_with_scratch<P: HasPosition>(
    points: &[P],
    trim: f64,
    scratch: &mut Vec<f64>,
) -> Result<Vector3<f64>, GeometryError> {
    if !(0.0..0.5).contains(&trim) {
        return Err(GeometryError::InvalidTrim(trim));
    }
    if points.is_empty() {
        return Err(GeometryError::EmptyInput);
    }
    if let Some(index) = points
        .iter()
        .position(|p| !p.position_m().iter().all(|c| c.is_finite()))
    {
        return Err(GeometryError::NonFinitePosition { index });
    }
    let n = points.len();
    // trim < 0.5 guarantees n - 2·cut >= 1.
    let cut = (trim * n as f64).floor() as usize;
    let mut c = Vector3::zeros();
    for axis in 0..3 {
        scratch.clear();
        scratch.extend(points.iter().map(|p| p.position_m()[axis]));
        c[axis] = trimmed_mean_in_place(scratch, cut);
    }
    Ok(c)
}

/// Mean of `values` without its `cut` smallest and `cut` largest entries
/// (Eq. 1 ordering obtained by two partial selections). Requires finite
/// values and `2·cut < values.len()`; reorders `values`.
fn trimmed_mean_in_place(values: &mut [f64], cut: usize) -> f64 {
    let keep = values.len() - 2 * cut;
    if cut > 0 {
        // values[..cut] become the `cut` smallest, values[cut..] the rest.
        values.select_nth_unstable_by(cut - 1, f64::total_cmp);
        // Within the rest (keep + cut values), [..keep] become the `keep` smallest.
        values[cut..].select_nth_unstable_by(keep, f64::total_cmp);
    }
    values[cut..cut + keep].iter().sum::<f64>() / keep as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    fn sorted_trimmed_mean(values: &[f64], cut: usize) -> f64 {
        let mut v = values.to_vec();
        v.sort_by(f64::total_cmp);
        let kept = &v[cut..v.len() - cut];
        kept.iter().sum::<f64>() / kept.len() as f64
    }

    #[test]
    fn plain_centroid_is_the_mean() {
        let pts = [Vector3::new(0.0, 0.0, 0.0), Vector3::new(2.0, 4.0, -6.0)];
        assert_eq!(centroid(&pts), Some(Vector3::new(1.0, 2.0, -3.0)));
        assert_eq!(centroid::<Vector3<f64>>(&[]), None);
        let bad = [Point::new(f32::NAN, 0.0, 0.0, 0.0, 0.0)];
        assert_eq!(centroid(&bad), None);
        let points = [
            Point::new(1.0, 2.0, 3.0, 0.0, 0.0),
            Point::new(3.0, 2.0, 1.0, 0.0, 9.0),
        ];
        assert_eq!(centroid(&points), Some(Vector3::new(2.0, 2.0, 2.0)));
    }

    #[test]
    fn selection_matches_a_full_sort() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for n in [1usize, 2, 3, 4, 5, 8, 17, 100, 1001] {
            for trim in [0.0, 0.1, 0.25, 0.4, 0.49] {
                let values: Vec<f64> = (0..n).map(|_| rng.random_range(-5.0..5.0)).collect();
                let cut = (trim * n as f64).floor() as usize;
                let mut scratch = values.clone();
                let fast = trimmed_mean_in_place(&mut scratch, cut);
                let slow = sorted_trimmed_mean(&values, cut);
                assert!(
                    (fast - slow).abs() < 1e-12,
                    "n={n} trim={trim}: {fast} vs {slow}"
                );
            }
        }
    }

    #[test]
    fn paper_formula_for_n_divisible_by_four() {
        // Eq. (2): c = 2/N Σ_{i=N/4+1}^{3N/4}, per axis with its own ordering.
        let pts: Vec<Vector3<f64>> = [1.0, 100.0, 3.0, -50.0, 2.0, 4.0, 7.0, 5.0]
            .iter()
            .enumerate()
            .map(|(i, &x)| Vector3::new(x, -(i as f64), 0.5))
            .collect();
        let c = trimmed_centroid(&pts, DEFAULT_TRIM).unwrap();
        // x sorted: -50 1 2 3 4 5 7 100 -> keep 2 3 4 5; y: -7..0 -> keep -5..-2.
        assert!((c.x - 3.5).abs() < 1e-12);
        assert!((c.y + 3.5).abs() < 1e-12);
        assert!((c.z - 0.5).abs() < 1e-12);
    }

    #[test]
    fn trimmed_centroid_resists_twenty_percent_outliers() {
        let mut rng = ChaCha8Rng::seed_from_u64(42);
        let noise = Normal::new(0.0, 0.05).unwrap();
        let centre = Vector3::new(1.0, 2.0, 10.0);
        let mut points: Vec<Point> = (0..1000)
            .map(|i| {
                let d = Vector3::from_fn(|_, _| noise.sample(&mut rng));
                Point::from_vector(&(centre + d), 1.0, i as f64)
            })
            .collect();
        // 200 ghost reflections (20 %), all on one side, metres away. One-sided
        // outliers make the 25 % trim keep inlier quantiles 0.3..0.9, a bias of
        // about 0.29 σ per axis (~2.5 cm in norm here) that no trimming avoids.
        for i in 0..200 {
            let d = Vector3::new(
                rng.random_range(3.0..8.0),
                rng.random_range(3.0..8.0),
                rng.random_range(5.0..15.0),
            );
            points.push(Point::from_vector(&(centre + d), 1.0, i as f64));
        }
        let trimmed = trimmed_centroid(&points, DEFAULT_TRIM).unwrap();
        let plain = centroid(&points).unwrap();
        let (e_trimmed, e_plain) = ((trimmed - centre).norm(), (plain - centre).norm());
        println!("trimmed centroid error {e_trimmed:.4} m, plain mean error {e_plain:.4} m");
        assert!(e_trimmed < 0.05, "trimmed {trimmed:?}");
        assert!(e_plain > 1.0, "plain {plain:?}");
        // Symmetric outliers cancel: the trimmed centroid is then unbiased.
        let mirrored: Vec<Point> = points[1000..]
            .iter()
            .map(|p| Point::from_vector(&(2.0 * centre - p.position()), 1.0, 0.0))
            .collect();
        points.extend(mirrored);
        let symmetric = trimmed_centroid(&points, DEFAULT_TRIM).unwrap();
        assert!(
            (symmetric - centre).norm() < 0.01,
            "symmetric {symmetric:?}"
        );
    }

    #[test]
    fn bad_inputs_are_errors() {
        let pts = [Vector3::new(1.0, 2.0, 3.0)];
        for trim in [-0.1, 0.5, 0.7, f64::NAN] {
            assert!(matches!(
                trimmed_centroid(&pts, trim),
                Err(GeometryError::InvalidTrim(_))
            ));
        }
        assert!(matches!(
            trimmed_centroid::<Vector3<f64>>(&[], 0.25),
            Err(GeometryError::EmptyInput)
        ));
        let with_nan = [
            Vector3::new(1.0, 2.0, 3.0),
            Vector3::new(0.0, f64::INFINITY, 0.0),
        ];
        assert!(matches!(
            trimmed_centroid(&with_nan, 0.25),
            Err(GeometryError::NonFinitePosition { index: 1 })
        ));
        assert_eq!(trimmed_centroid(&pts, 0.49).unwrap(), pts[0]);
    }
}
