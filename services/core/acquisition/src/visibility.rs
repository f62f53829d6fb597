//! The reverse check of a refined pose (not in seed 002): does the sensor
//! see what the model, at that pose, says it should see?
//!
//! f_CONV (seed 002 §4.5) measures how close the sensed points lie to the
//! model; it cannot see a model part that the pose puts in view but the
//! sensor did not return. On sparse far-range clouds (80 points at 50 m) a
//! 180° flip of ENVISAT fits the points as well as the true pose (f_CONV
//! under 1e-3 m² on both), but its template, rendered at the flipped pose,
//! shows the solar array or the antenna where the sensor saw nothing.
//!
//! The check renders that template (noise-free, the sensor's own rays) and
//! counts the template points with no sensed point within `k` ray
//! spacings (the spacing at the point's range): the *unexplained
//! fraction*. A ray lost to detection leaves its neighbours one spacing
//! away, so the true pose explains nearly every template point, while a
//! model part in empty space is unexplained as a whole.

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::Vector3;

/// The sensed cloud prepared for the reverse check.
pub struct SensedTree {
    tree: Option<ImmutableKdTree<f64, 3>>,
}

impl SensedTree {
    /// A kd-tree over `points` (sensor frame).
    pub fn new(points: &[Vector3<f64>]) -> Self {
        let entries: Vec<[f64; 3]> = points.iter().map(|p| [p.x, p.y, p.z]).collect();
        let tree = if entries.is_empty() {
            None
        } else {
            ImmutableKdTree::new_from_slice(&entries).ok()
        };
        Self { tree }
    }

    /// Fraction of `template` (sensor frame) whose nearest sensed point is
    /// farther than `tolerance_rad` times the template point's range. 1 for
    /// an empty template or cloud: a pose that puts nothing in view
    /// explains nothing.
    pub fn unexplained_fraction(&self, template: &[Vector3<f64>], tolerance_rad: f64) -> f64 {
        let Some(tree) = &self.tree else {
            return 1.0;
        };
        if template.is_empty() {
            return 1.0;
        }
        let unexplained = template
            .iter()
            .filter(|p| {
                let d2 = tree
                    .query(&[p.x, p.y, p.z])
                    .nearest_one::<SquaredEuclidean<f64>>()
                    .execute()
                    .distance;
                let tol = tolerance_rad * p.norm();
                d2 > tol * tol
            })
            .count();
        unexplained as f64 / template.len() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 10 × 10 grid of points 0.5 m apart at 30 m (about 1° apart).
    fn panel(x0: f64) -> Vec<Vector3<f64>> {
        (0..10)
            .flat_map(|i| {
                (0..10).map(move |j| Vector3::new(x0 + i as f64 * 0.5, j as f64 * 0.5, 30.0))
            })
            .collect()
    }

    #[test]
    fn a_template_part_the_sensor_did_not_see_is_unexplained() {
        let sensed = panel(0.0);
        let tree = SensedTree::new(&sensed);
        let spacing = 0.5 / 30.0;
        assert_eq!(tree.unexplained_fraction(&sensed, 1.5 * spacing), 0.0);
        // Every other sensed point lost: the neighbours still explain them.
        let sparse: Vec<_> = sensed.iter().copied().step_by(2).collect();
        let tree_sparse = SensedTree::new(&sparse);
        assert_eq!(
            tree_sparse.unexplained_fraction(&sensed, 1.5 * spacing),
            0.0
        );
        // A second panel 10 m away that the sensor did not return.
        let mut template = panel(0.0);
        template.extend(panel(10.0));
        assert_eq!(tree.unexplained_fraction(&template, 1.5 * spacing), 0.5);
        // Empty inputs explain nothing.
        assert_eq!(tree.unexplained_fraction(&[], 1.0), 1.0);
        assert_eq!(SensedTree::new(&[]).unexplained_fraction(&sensed, 1.0), 1.0);
    }
}
