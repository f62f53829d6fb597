//! One acquisition method behind a common interface, so the init service can
//! try several in order (issue 6: the CNN first, template matching as the
//! fallback) and report which one succeeded.

use crate::error::InitError;
use spacepose_geometry::{Point, Pose};
use spacepose_messages::AcquisitionMethod;

/// What a method found on one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodOutput {
    /// The estimate of `t_sensor_target` (after refinement).
    pub t_sensor_target: Pose,
    /// f_CONV, the refinement cost at convergence (m², seed 002 §4.5).
    pub f_conv_m2: f64,
    /// True when the method's own failure check passed (`f_CONV <= f_MAX`).
    pub accepted: bool,
    /// One line for the log (templates evaluated, ICP iterations, ...).
    pub detail: String,
}

/// A pose acquisition method: one frame in, an estimate and its verdict out.
/// Implementations are libraries without any bus.
pub trait PoseAcquirer: Send {
    /// Which method this is (written into the published result).
    fn method(&self) -> AcquisitionMethod;

    /// Acquires the pose from one ingest-filtered frame in the sensor frame.
    /// Input it cannot use (too few points, all outliers) is an `Err` or an
    /// output with `accepted == false`, never an accepted pose.
    fn acquire(&self, cloud: &[Point]) -> Result<MethodOutput, InitError>;
}

/// One method's try on one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Attempt {
    /// The method tried.
    pub method: AcquisitionMethod,
    /// Its output, or why it could not run.
    pub outcome: Result<MethodOutput, InitError>,
    /// Wall time of the attempt (ms).
    pub time_ms: f64,
}

impl Attempt {
    /// True when the method produced a pose that passed its failure check.
    pub fn accepted(&self) -> bool {
        matches!(&self.outcome, Ok(o) if o.accepted)
    }

    /// f_CONV of the output, when there is one.
    pub fn f_conv_m2(&self) -> Option<f64> {
        self.outcome.as_ref().ok().map(|o| o.f_conv_m2)
    }
}
