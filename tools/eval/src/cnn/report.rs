//! The scored results of `eval cnn`: one record per held-out frame and the
//! summary of a run (Tables III and IV, f_CONV, success by range).

use crate::stats::median;
use serde::Serialize;
use spacepose_cnn::EstimatorConfig;

/// One held-out frame, scored.
#[derive(Debug, Clone, Serialize)]
pub struct CnnFrame {
    /// Frame index.
    pub frame: u64,
    /// True range of the centre of mass (m).
    pub range_m: f64,
    /// Points in the frame.
    pub points: usize,
    /// Angular rate of the target (deg/s): motion blur.
    pub rate_deg_s: f64,
    /// Time spanned by the points (s).
    pub scan_s: f64,
    /// Attitude error of the network's pose (deg, d_sym).
    pub raw_err_deg: f64,
    /// Position error of the network's pose (cm).
    pub raw_err_cm: f64,
    /// Attitude error after refinement (deg, d_sym).
    pub err_deg: f64,
    /// Position error after refinement (cm).
    pub err_cm: f64,
    /// Raw pose within 5° and 15 cm.
    pub success_raw: bool,
    /// Refined pose within 5° and 15 cm.
    pub success_refined: bool,
    /// f_CONV (m²).
    pub f_conv_m2: f64,
    /// f_CONV ≤ f_MAX.
    pub accepted: bool,
    /// The twin check.
    pub twins: spacepose_cnn::TwinOutcome,
    /// Probability of the top class.
    pub top_probability: f32,
    /// Hypothesis of the reported pose (0 = Γ_sym's).
    pub hypothesis: usize,
    /// Hypotheses refined.
    pub hypotheses_refined: usize,
    /// Run time split (ms).
    pub time_ms: spacepose_cnn::Timings,
    /// Of the refinement: the f_CONV ICP (ms).
    pub fconv_ms: f64,
    /// The estimator's error or the refinement's, if any.
    pub error: Option<String>,
}

/// Mean ± standard deviation over the successes (Table III).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct MeanStd {
    /// Mean.
    pub mean: f64,
    /// Standard deviation.
    pub std: f64,
}

impl MeanStd {
    pub(crate) fn of(values: &[f64]) -> Self {
        let n = values.len() as f64;
        if values.is_empty() {
            return Self {
                mean: f64::NAN,
                std: f64::NAN,
            };
        }
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
        Self {
            mean,
            std: var.sqrt(),
        }
    }
}

/// Errors before and after refinement.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct RawRefined {
    /// Network pose, over its successes.
    pub raw: MeanStd,
    /// Refined pose, over its successes.
    pub refined: MeanStd,
}

/// Median, mean and standard deviation of a time (ms).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct TimeStats {
    /// Median.
    pub median: f64,
    /// Mean.
    pub mean: f64,
    /// Standard deviation.
    pub std: f64,
    /// 95th percentile.
    pub p95: f64,
}

impl TimeStats {
    pub(crate) fn of(values: &[f64]) -> Self {
        let MeanStd { mean, std } = MeanStd::of(values);
        let mut sorted = values.to_vec();
        sorted.sort_by(f64::total_cmp);
        let p95 = sorted
            .get(((sorted.len() as f64 * 0.95) as usize).min(sorted.len().saturating_sub(1)))
            .copied()
            .unwrap_or(f64::NAN);
        Self {
            median: median(values),
            mean,
            std,
            p95,
        }
    }
}

/// Table IV.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct TimeSplit {
    /// Finite-point filter, trimmed centroid, depth image.
    pub preprocess: TimeStats,
    /// Network and Γ_sym.
    pub inference: TimeStats,
    /// Voxel filter, NDT, f_CONV ICP.
    pub refinement: TimeStats,
    /// Everything.
    pub total: TimeStats,
}

/// f_CONV over successes and failures (seed 002 Table 4), to choose f_MAX.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct FconvStats {
    /// f_MAX used (m²).
    pub f_max_m2: f64,
    /// Accepted over frames.
    pub accepted_rate: f64,
    /// Accepted failures (a wrong pose handed to the tracker).
    pub false_accepts: usize,
    /// Rejected successes (template matching would be tried needlessly).
    pub false_rejects: usize,
    /// Largest f_CONV of a refined success (m²).
    pub success_max_m2: f64,
    /// Median f_CONV of the successes.
    pub success_median_m2: f64,
    /// Smallest f_CONV of a refined failure (m²).
    pub failure_min_m2: f64,
    /// Median f_CONV of the failures.
    pub failure_median_m2: f64,
}

/// Success by range.
#[derive(Debug, Clone, Serialize)]
pub struct RangeBin {
    /// Range interval (m).
    pub range_m: [f64; 2],
    /// Frames in it.
    pub frames: usize,
    /// Refined successes over frames.
    pub success_rate_refined: f64,
    /// Raw successes over frames.
    pub success_rate_raw: f64,
    /// Accepted (f_CONV) and a refined success, over frames: what init
    /// hands the tracker that it may use.
    pub accepted_correct_rate: f64,
    /// Accepted and not a refined success, over frames: a wrong pose
    /// handed to the tracker as a success.
    pub false_accept_rate: f64,
}

/// Summary of an `eval cnn` run.
#[derive(Debug, Clone, Serialize)]
pub struct CnnReport {
    /// Target name.
    pub target: String,
    /// Model directory.
    pub model: String,
    /// Engine (`tract` or `ort`).
    pub engine: String,
    /// Seed of the held-out set.
    pub seed: u64,
    /// The frames came from outside the training (`--mismatch`).
    pub mismatch: bool,
    /// Frames.
    pub count: usize,
    /// Refined successes over frames.
    pub success_rate_refined: f64,
    /// Network successes over frames.
    pub success_rate_raw: f64,
    /// Accepted (f_CONV) and a refined success, over frames (issue 25
    /// item 4): what init hands the tracker that it may use.
    pub accepted_correct_rate: f64,
    /// Accepted and not a refined success, over frames: a wrong pose handed
    /// to the tracker as a success.
    pub false_accept_rate: f64,
    /// Attitude errors over the successes (deg).
    pub ang_err_deg: RawRefined,
    /// Position errors over the successes (cm).
    pub pos_err_cm: RawRefined,
    /// Run time split (ms), one thread.
    pub time_ms: TimeSplit,
    /// Acceptance check.
    pub fconv: FconvStats,
    /// Success by range.
    pub by_range: Vec<RangeBin>,
    /// Estimator errors (counted as failures).
    pub errors: usize,
    /// Frames whose reported pose comes from another hypothesis than Γ_sym's.
    pub other_hypothesis: usize,
    /// Frames where more than one hypothesis was refined.
    pub several_hypotheses: usize,
    /// Frames where the twin check refined a twin.
    pub twins_refined: usize,
    /// Frames whose reported pose is a twin's refinement.
    pub twin_used: usize,
    /// Mean points per frame.
    pub mean_points: f64,
    /// Estimator settings.
    pub config: EstimatorConfig,
    /// Every frame.
    pub frames: Vec<CnnFrame>,
}
