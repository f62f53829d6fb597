//! The interface every scenario offers.

use crate::truth::TruthState;
use spacepose_geometry::Pose;

/// A relative-motion scenario with ground truth, deterministic given its seed.
pub trait Scenario: Send + Sync {
    /// The scenario name (`slow-spin`, `tumbling`, `ellipse`, `random`).
    fn name(&self) -> &str;

    /// Natural duration (s) after compression: the last frame of
    /// [`Scenario::natural_frame_count`] ends at `frame_period_s + duration_s`.
    fn duration_s(&self) -> f64;

    /// Scan end time of each of `frames` frames: `frame_period_s`,
    /// `2 frame_period_s`, … (the first frame ends one period after `t = 0`
    /// so a whole scan fits before it).
    fn frame_end_times(&self, frames: usize) -> Vec<f64>;

    /// The relative state at time `t` (s). Continuous in `t` except for the
    /// random scenario, whose frames are independent by design.
    fn state_at(&self, t: f64) -> TruthState;

    /// Only the pose at `t`; cheaper than [`Scenario::state_at`] when called
    /// once per lidar point.
    fn pose_at(&self, t: f64) -> Pose {
        self.state_at(t).t_sensor_target
    }

    /// Time between two frames (s).
    fn frame_period_s(&self) -> f64 {
        1.0
    }

    /// Number of frames covering the whole scenario, both ends included
    /// (seed 002's ellipse: 241).
    fn natural_frame_count(&self) -> usize {
        let n = self.duration_s() / self.frame_period_s();
        if n.is_finite() && n >= 0.0 {
            (n + 1e-9).floor() as usize + 1
        } else {
            0
        }
    }
}

/// `frames` end times spaced by `period`, the first at `period`.
pub(crate) fn evenly_spaced_end_times(period: f64, frames: usize) -> Vec<f64> {
    (0..frames).map(|k| (k + 1) as f64 * period).collect()
}
