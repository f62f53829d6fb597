//! Construction of the kiddo kd-trees used by the map and by ICP.

use crate::error::RegistrationError;
use kiddo::ImmutableKdTree;
use nalgebra::Vector3;

/// A 3-D kd-tree whose items are the indices of the points it was built from.
pub(crate) type Tree3 = ImmutableKdTree<f64, 3>;

/// Builds a [`Tree3`] over `points` (item `i` = `points[i]`).
pub(crate) fn build_tree(points: &[Vector3<f64>]) -> Result<Tree3, RegistrationError> {
    let entries: Vec<[f64; 3]> = points.iter().map(|p| [p.x, p.y, p.z]).collect();
    ImmutableKdTree::new_from_slice(&entries)
        .map_err(|e| RegistrationError::InvalidModel(format!("kd-tree construction: {e}")))
}
