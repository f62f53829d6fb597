//! The correlation C of seed 002 Eq. (1) after centroid alignment, and the
//! boresight distribution D_BOR of Eq. (2) with the test of Eq. (3).

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::Vector3;
use spacepose_geometry::centroid;
use spacepose_geometry::centroid::trimmed_centroid_with_scratch;

/// D_BOR of Eq. (2): the mean distance of the points from the boresight
/// (sensor z axis), `1/N Σ sqrt(x² + y²)`. 0 for an empty cloud.
pub fn d_bor(points: &[Vector3<f64>]) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    points.iter().map(|p| p.x.hypot(p.y)).sum::<f64>() / points.len() as f64
}

/// Eq. (3): the template passes when its D_BOR differs from the sensor's by
/// at most `tau` relative to the sensor's.
pub fn d_bor_passes(d_bor_sensor: f64, d_bor_template: f64, tau: f64) -> bool {
    (d_bor_sensor - d_bor_template).abs() <= tau * d_bor_sensor
}

/// How clouds are centred before association (seed 002 §2.1: the template
/// is translated so that the centroids coincide).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Centering {
    /// The mean.
    Mean,
    /// The trimmed centroid of seed 004 Eqs. (1)-(2) with this trim factor.
    Trimmed(f64),
}

impl Centering {
    /// The centre of `points`, or `None` for an empty or non-finite cloud.
    pub fn centre(&self, points: &[Vector3<f64>], scratch: &mut Vec<f64>) -> Option<Vector3<f64>> {
        match *self {
            Centering::Mean => centroid(points),
            Centering::Trimmed(trim) => trimmed_centroid_with_scratch(points, trim, scratch).ok(),
        }
    }
}

/// The sensor side of Eq. (1), prepared once per acquisition: the sensor
/// points relative to their centre (optionally a subsample).
pub struct Correlator {
    centred: Vec<[f64; 3]>,
    centering: Centering,
    /// kd-tree over `centred` for the symmetric variant.
    sensor_tree: Option<ImmutableKdTree<f64, 3>>,
}

impl std::fmt::Debug for Correlator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Correlator")
            .field("points", &self.centred.len())
            .field("centering", &self.centering)
            .field("symmetric", &self.sensor_tree.is_some())
            .finish()
    }
}

impl Correlator {
    /// `sensor` (finite points, sensor frame) centred on `sensor_centre`.
    /// With `max_points > 0` and more points than that, an evenly strided
    /// subsample of about `max_points` is used (a cheaper C). With
    /// `symmetric`, C also averages the template-to-sensor distances (see
    /// [`Correlator::correlation`]).
    pub fn new(
        sensor: &[Vector3<f64>],
        sensor_centre: &Vector3<f64>,
        centering: Centering,
        max_points: usize,
        symmetric: bool,
    ) -> Self {
        let stride = if max_points > 0 && sensor.len() > max_points {
            sensor.len().div_ceil(max_points)
        } else {
            1
        };
        let centred = sensor
            .iter()
            .step_by(stride)
            .map(|p| {
                let c = p - sensor_centre;
                [c.x, c.y, c.z]
            })
            .collect::<Vec<_>>();
        let sensor_tree = if symmetric && !centred.is_empty() {
            ImmutableKdTree::new_from_slice(&centred).ok()
        } else {
            None
        };
        Self {
            centred,
            centering,
            sensor_tree,
        }
    }

    /// How clouds are centred.
    pub fn centering(&self) -> Centering {
        self.centering
    }

    /// Points used in Eq. (1).
    pub fn len(&self) -> usize {
        self.centred.len()
    }

    /// True without any point.
    pub fn is_empty(&self) -> bool {
        self.centred.is_empty()
    }

    /// C of Eq. (1): the mean squared distance from each sensor point to its
    /// nearest template point (kiddo kd-tree), after translating the
    /// template so that the centres coincide. Also returns the template's
    /// centre (sensor frame, before translation). `None` for a template with
    /// fewer than 3 points.
    ///
    /// Symmetric variant (not in seed 002): the mean of Eq. (1) and of the
    /// same mean taken from the template points to the sensor cloud, so a
    /// template showing parts the sensor does not see is penalised too.
    pub fn correlation(
        &self,
        template: &[Vector3<f64>],
        scratch: &mut Vec<f64>,
    ) -> Option<(f64, Vector3<f64>)> {
        if template.len() < 3 || self.centred.is_empty() {
            return None;
        }
        let centre = self.centering.centre(template, scratch)?;
        let entries: Vec<[f64; 3]> = template
            .iter()
            .map(|p| {
                let c = p - centre;
                [c.x, c.y, c.z]
            })
            .collect();
        let tree: ImmutableKdTree<f64, 3> = ImmutableKdTree::new_from_slice(&entries).ok()?;
        let sum: f64 = self
            .centred
            .iter()
            .map(|q| {
                tree.query(q)
                    .nearest_one::<SquaredEuclidean<f64>>()
                    .execute()
                    .distance
            })
            .sum();
        let mut c = sum / self.centred.len() as f64;
        if let Some(sensor_tree) = &self.sensor_tree {
            let back: f64 = entries
                .iter()
                .map(|q| {
                    sensor_tree
                        .query(q)
                        .nearest_one::<SquaredEuclidean<f64>>()
                        .execute()
                        .distance
                })
                .sum();
            c = 0.5 * (c + back / entries.len() as f64);
        }
        Some((c, centre))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube_cloud() -> Vec<Vector3<f64>> {
        let mut v = Vec::new();
        for i in 0..8 {
            for j in 0..8 {
                v.push(Vector3::new(
                    i as f64 * 0.3,
                    j as f64 * 0.3,
                    20.0 + 0.1 * i as f64,
                ));
                v.push(Vector3::new(i as f64 * 0.3, 2.1, 20.0 + 0.2 * j as f64));
            }
        }
        v
    }

    #[test]
    fn correlation_of_a_cloud_with_itself_is_zero() {
        let cloud = cube_cloud();
        let mut s = Vec::new();
        for centering in [Centering::Mean, Centering::Trimmed(0.25)] {
            let c0 = centering.centre(&cloud, &mut s).unwrap();
            let corr = Correlator::new(&cloud, &c0, centering, 0, false);
            let (c, centre) = corr.correlation(&cloud, &mut s).unwrap();
            assert!(c < 1e-20, "{c}");
            assert!((centre - c0).norm() < 1e-12);
            // A translated copy is aligned by the centroids: still zero.
            let moved: Vec<_> = cloud
                .iter()
                .map(|p| p + Vector3::new(1.0, -2.0, 3.0))
                .collect();
            assert!(corr.correlation(&moved, &mut s).unwrap().0 < 1e-20);
            // A rotated copy is not.
            let r = nalgebra::Rotation3::from_euler_angles(0.0, 0.0, 0.5);
            let turned: Vec<_> = cloud.iter().map(|p| r * p).collect();
            assert!(corr.correlation(&turned, &mut s).unwrap().0 > 1e-3);
        }
    }

    #[test]
    fn d_bor_test_of_eq_3() {
        let cloud = cube_cloud();
        let d = d_bor(&cloud);
        assert!(d > 0.5);
        assert!(d_bor_passes(d, d * 1.05, 0.1));
        assert!(!d_bor_passes(d, d * 1.2, 0.1));
        assert!(!d_bor_passes(d, d * 0.8, 0.1));
        assert_eq!(d_bor(&[]), 0.0);
    }

    #[test]
    fn tiny_template_gives_none() {
        let cloud = cube_cloud();
        let corr = Correlator::new(&cloud, &Vector3::zeros(), Centering::Mean, 0, false);
        assert!(corr.correlation(&cloud[..2], &mut Vec::new()).is_none());
        assert_eq!(
            Correlator::new(&cloud, &Vector3::zeros(), Centering::Mean, 10, false).len(),
            10
        );
    }
}
