//! Validation of the inputs shared by every registration.

use crate::error::RegistrationError;
use nalgebra::Vector3;
use spacepose_geometry::{Point, Pose};

/// The finite points of a source cloud in f64, and how many were skipped.
///
/// Errors: [`RegistrationError::EmptyCloud`] for an empty slice,
/// [`RegistrationError::AllPointsNonFinite`] when nothing is left.
pub(crate) fn finite_positions(
    source: &[Point],
) -> Result<(Vec<Vector3<f64>>, usize), RegistrationError> {
    if source.is_empty() {
        return Err(RegistrationError::EmptyCloud);
    }
    let points: Vec<Vector3<f64>> = source
        .iter()
        .filter(|p| position_is_finite(p))
        .map(Point::position)
        .collect();
    if points.is_empty() {
        return Err(RegistrationError::AllPointsNonFinite {
            count: source.len(),
        });
    }
    let skipped = source.len() - points.len();
    Ok((points, skipped))
}

/// True when the three coordinates are finite (intensity and time are not
/// looked at).
#[inline]
pub(crate) fn position_is_finite(p: &Point) -> bool {
    p.x.is_finite() && p.y.is_finite() && p.z.is_finite()
}

/// Rejects an initial pose with a non-finite entry.
pub(crate) fn check_pose(name: &'static str, pose: &Pose) -> Result<(), RegistrationError> {
    if pose.is_finite() {
        Ok(())
    } else {
        Err(RegistrationError::param(
            name,
            "pose has a non-finite entry",
        ))
    }
}
