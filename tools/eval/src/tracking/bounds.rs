//! The eval's one far-off bound: frames, acquisitions and tables use it.

/// A frame whose error exceeds these has lost the target in truth, whatever
/// the tracker reports.
pub const DIVERGED_DEG: f64 = 10.0;
/// See [`DIVERGED_DEG`] (m).
pub const DIVERGED_M: f64 = 0.5;

use nalgebra::Rotation3;
use spacepose_geometry::{Pose, so3};

/// The eval's one error of an estimate against the truth: the attitude
/// error (deg; d_sym of seed 004 Eq. 14 over `symmetries`, d when empty)
/// and the distance between the centres of mass (m).
pub fn pose_error(estimate: &Pose, truth: &Pose, symmetries: &[Rotation3<f64>]) -> (f64, f64) {
    let ang = so3::distance_sym(&estimate.rotation, &truth.rotation, symmetries);
    (
        ang.to_degrees(),
        (estimate.translation - truth.translation).norm(),
    )
}

/// More than [`DIVERGED_DEG`] or [`DIVERGED_M`] off; NaN errors count.
pub fn far_off(ang_deg: f64, pos_m: f64) -> bool {
    !(ang_deg <= DIVERGED_DEG && pos_m <= DIVERGED_M)
}
