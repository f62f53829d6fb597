//! What one simulated scan holds: the points, what produced each of them,
//! the scan window and the ground truth.

use spacepose_geometry::Point;
use spacepose_scenario::TruthState;

/// Reported intensity = received return factor (m⁻²) × this reference area:
/// a white Lambertian surface at normal incidence 10 m away reads 1.
pub const INTENSITY_REFERENCE_M2: f64 = 100.0;

/// What produced a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ReturnKind {
    /// An echo of the target (possibly mixed by divergence or reflections).
    Target,
    /// An echo of the test-facility background (`Effects::clutter`).
    Clutter,
    /// A point drawn as an outlier (range σ = 4 σ_RANGE, seed 002).
    Outlier,
}

/// One simulated scan.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Points in the sensor frame, in scan (time) order.
    pub points: Vec<Point>,
    /// What produced each point (same length and order as `points`).
    pub kinds: Vec<ReturnKind>,
    /// Start of the scan window (s): `scan_end - integration_time`.
    pub scan_start: f64,
    /// End of the scan window (s), the time of `truth`.
    pub scan_end: f64,
    /// Ground truth at scan end.
    pub truth: TruthState,
}
