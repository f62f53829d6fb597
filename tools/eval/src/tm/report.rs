//! The scored results of `eval tm`: one record per acquisition and the
//! summary of a run (seed 002 Tables 2 and 4).

use super::args::SensorEffects;
use crate::stats::MeanMax;
use serde::Serialize;
use spacepose_acquisition::TemplateMatchingConfig;

/// One acquisition, scored.
#[derive(Debug, Clone, Serialize)]
pub struct TmFrame {
    /// Frame index.
    pub frame: usize,
    /// True range of the centre of mass (m).
    pub range_m: f64,
    /// Points in the frame.
    pub points: usize,
    /// Attitude error after ICP (deg, d_sym); NaN without a pose.
    pub err_deg: f64,
    /// Position error after ICP (m).
    pub err_m: f64,
    /// Attitude error of the template solution (deg, d_sym).
    pub coarse_err_deg: f64,
    /// |Δ| of yaw, pitch, roll of the template solution (deg).
    pub coarse_euler_err_deg: [f64; 3],
    /// err_deg < 3°.
    pub success: bool,
    /// f_CONV (m²), infinite when no refinement.
    pub f_conv_m2: f64,
    /// Unexplained fraction of the solution (see
    /// `spacepose_acquisition::visibility`), 1 when no refinement.
    pub unexplained_fraction: f64,
    /// The acquisition accepted the solution (f_CONV ≤ f_MAX and
    /// unexplained fraction ≤ U_MAX).
    pub accepted: bool,
    /// Acquisition time (ms).
    pub time_ms: f64,
    /// Of which template matching (ms).
    pub matching_ms: f64,
    /// Of which ICP (ms).
    pub refinement_ms: f64,
    /// Templates rendered.
    pub templates_generated: usize,
    /// Templates correlated.
    pub templates_evaluated: usize,
    /// The acquisition error, if any (counted as a failure).
    pub error: Option<String>,
    /// The solution, target body → sensor: `[x, y, z, qw, qx, qy, qz]`
    /// (m; unit quaternion); `None` without one. For diagnostics against
    /// the frames `spacepose sim` writes for the same scenario and seed.
    pub t_sensor_target: Option<[f64; 7]>,
}

/// Means of the template counts.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct TemplateCounts {
    /// Templates rendered per acquisition.
    pub generated: f64,
    /// Templates correlated per acquisition.
    pub evaluated: f64,
    /// Grid size.
    pub grid: usize,
}

/// Summary of an `eval tm` run.
#[derive(Debug, Clone, Serialize)]
pub struct TmReport {
    /// Target name.
    pub target: String,
    /// Scenario name.
    pub scenario: String,
    /// Range (random scenario) or NaN.
    pub range_m: f64,
    /// Seed.
    pub seed: u64,
    /// Sensor effects of the frames.
    pub sensor_effects: SensorEffects,
    /// The sensor.
    pub sensor: super::TmSensor,
    /// Frames.
    pub count: usize,
    /// Matching configuration.
    pub config: TemplateMatchingConfig,
    /// Successes over frames.
    pub success_rate: f64,
    /// Accepted (f_CONV ≤ f_MAX and unexplained fraction ≤ U_MAX) over
    /// frames.
    pub accepted_rate: f64,
    /// Accepted successes over frames: how often a frame gives tracking a
    /// correct pose it may use.
    pub accepted_success_rate: f64,
    /// Accepted failures.
    pub false_accepts: usize,
    /// Rejected successes.
    pub false_rejects: usize,
    /// Acquisition time (ms).
    pub time_ms: MeanMax,
    /// Template-matching part (ms).
    pub matching_ms: MeanMax,
    /// ICP part (ms).
    pub refinement_ms: MeanMax,
    /// Template counts.
    pub templates: TemplateCounts,
    /// Mean |Δ yaw|, |Δ pitch|, |Δ roll| of the template solution over the
    /// successes (deg, seed 002 Table 2).
    pub euler_err_deg: [f64; 3],
    /// Mean attitude error after ICP over the successes (deg).
    pub err_deg_success_mean: f64,
    /// f_CONV over the successes (m², Table 4).
    pub fconv_success_max: f64,
    /// Mean f_CONV over the successes.
    pub fconv_success_mean: f64,
    /// f_CONV over the failures (m², Table 4).
    pub fconv_failure_min: f64,
    /// Mean f_CONV over the failures.
    pub fconv_failure_mean: f64,
    /// `fconv_success_max < fconv_failure_min`.
    pub separable: bool,
    /// Unexplained fraction over the successes (max).
    pub unexplained_success_max: f64,
    /// Unexplained fraction over the failures that f_CONV alone would
    /// accept (min; NaN without such failures).
    pub unexplained_failure_min: f64,
    /// Mean points per frame.
    pub mean_points: f64,
    /// Every frame.
    pub frames: Vec<TmFrame>,
}
