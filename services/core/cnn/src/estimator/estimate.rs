//! What one estimate reports: the poses, the f_CONV check, the network's
//! top class, the counts and the run time split.

use crate::twins::TwinOutcome;
use serde::Serialize;
use spacepose_geometry::Pose;

/// Run time of one estimate, split as seed 004 Table IV (ms).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Timings {
    /// Finite-point filter, trimmed centroid and depth image.
    pub preprocess: f64,
    /// Network and Γ_sym decoding.
    pub inference: f64,
    /// Voxel filter, NDT, the f_CONV ICP and the twin check.
    pub refinement: f64,
    /// Everything.
    pub total: f64,
}

/// One estimate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CnnEstimate {
    /// The network's pose (Γ_sym attitude, ROI centre + offset).
    pub t_sensor_target_raw: Pose,
    /// The NDT-refined pose; the raw pose when the refinement failed.
    pub t_sensor_target: Pose,
    /// f_CONV (m²); infinite when the refinement failed.
    pub f_conv_m2: f64,
    /// `f_CONV <= f_MAX`: the pose may be used.
    pub accepted: bool,
    /// The twin check of the refined pose (default when the refinement
    /// failed).
    pub twins: TwinOutcome,
    /// Class of largest probability.
    pub top_class: usize,
    /// Its probability.
    pub top_probability: f32,
    /// Finite points of the cloud.
    pub points: usize,
    /// Points inside the ROI.
    pub points_in_roi: usize,
    /// Which hypothesis the reported pose comes from (0 = Γ_sym's).
    pub hypothesis: usize,
    /// Hypotheses refined.
    pub hypotheses_refined: usize,
    /// NDT iterations (all stages) of the reported hypothesis.
    pub ndt_iterations: usize,
    /// The final NDT stage converged.
    pub ndt_converged: bool,
    /// Why the refinement failed, if it did.
    pub refinement_error: Option<String>,
    /// Run time split.
    pub time_ms: Timings,
    /// Of the refinement: the f_CONV ICP (ms).
    pub fconv_ms: f64,
}
