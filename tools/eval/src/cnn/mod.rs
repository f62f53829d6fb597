//! `spacepose eval cnn`: seed 004's CNN pose estimation with NDT refinement
//! on a held-out synthetic set, scored against truth as Table III (success
//! before and after refinement: < 5° with d_sym, Eq. 14, and < 15 cm; mean
//! errors over the successes) and timed as Table IV (preprocessing,
//! inference, refinement; one thread).
//!
//! Frames come from the training set's generator (`spacepose_cnn::Generator`:
//! domain-randomised Mid-40 frames at 2.5-20 m with motion blur) with a seed
//! never used for training (training 1, validation 2, smoke 90). They are
//! simulated in parallel, chunk by chunk; the estimates then run one after
//! the other on the calling thread, so the timings are those of one core.

mod render;

use crate::common::load_target;
use crate::common::progress_bar;
use crate::stats::median;
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use rayon::prelude::*;
use serde::Serialize;
use spacepose_cnn::{
    CnnEstimator, DEFAULT_MIN_POINTS, DatasetConfig, EstimatorConfig, GeneratedFrame, Generator,
};
use spacepose_geometry::{Pose, so3};
use spacepose_inference::{Engine, find_ort_library};
use std::path::PathBuf;

/// Success thresholds of seed 004 §V.A.
pub const SUCCESS_DEG: f64 = 5.0;
/// Position threshold (cm).
pub const SUCCESS_CM: f64 = 15.0;
/// Seeds used for training, validation and the smoke set: refused.
pub const TRAINING_SEEDS: [u64; 3] = [1, 2, 90];
/// Frames simulated in parallel before they are estimated in turn.
const CHUNK: usize = 64;

/// Inference engines.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum EngineArg {
    /// tract-onnx (pure Rust).
    Tract,
    /// ONNX Runtime (build with `--features ort`).
    Ort,
}

/// `spacepose eval cnn`.
#[derive(Debug, Args)]
pub struct EvalCnnArgs {
    /// Built-in target or mesh file (the model must be trained for it).
    #[arg(long, default_value = "deos")]
    pub target: String,
    /// Model directory (model.onnx + model.json); default services/core/cnn/models/<target>.
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Held-out frames.
    #[arg(long, default_value_t = 1000, value_parser = clap::value_parser!(u64).range(1..))]
    pub count: u64,
    /// Seed of the held-out set (never 1, 2 or 90: training, validation, smoke).
    #[arg(long, default_value_t = 1001)]
    pub seed: u64,
    /// Inference engine.
    #[arg(long, value_enum, default_value = "tract")]
    pub engine: EngineArg,
    /// ONNX Runtime library (default: $ORT_DYLIB_PATH or tools/train/.venv's wheel).
    #[arg(long)]
    pub ort_library: Option<PathBuf>,
    /// f_MAX (m²) of the acceptance check (default: the estimator's).
    #[arg(long)]
    pub f_max: Option<f64>,
    /// Wider NDT stages before the final 7.5 cm one (m, comma-separated;
    /// "none" for the paper's single stage). Default: the estimator's.
    #[arg(long)]
    pub ndt_stages: Option<String>,
    /// Attitude hypotheses refined at most (1 = the paper). Default: the estimator's.
    #[arg(long)]
    pub hypotheses: Option<usize>,
    /// Points kept for the refinement (0 = all). Default: the estimator's.
    #[arg(long)]
    pub max_points: Option<usize>,
    /// Threads simulating the frames (default: all cores); estimates use one.
    #[arg(long)]
    pub sim_threads: Option<usize>,
    /// Write the report as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Also list every frame.
    #[arg(long)]
    pub frames: bool,
}

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
    fn of(values: &[f64]) -> Self {
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
    fn of(values: &[f64]) -> Self {
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
    /// Frames.
    pub count: usize,
    /// Refined successes over frames.
    pub success_rate_refined: f64,
    /// Network successes over frames.
    pub success_rate_raw: f64,
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

fn engine(args: &EvalCnnArgs) -> Result<Engine> {
    Ok(match args.engine {
        EngineArg::Tract => Engine::Tract,
        EngineArg::Ort => Engine::Ort {
            library: match &args.ort_library {
                Some(p) => p.clone(),
                None => find_ort_library()?,
            },
        },
    })
}

/// Errors of `estimate` against the truth: (deg with d_sym, cm).
fn errors(estimate: &Pose, truth: &Pose, syms: &[nalgebra::Rotation3<f64>]) -> (f64, f64) {
    let deg = so3::distance_sym(&estimate.rotation, &truth.rotation, syms).to_degrees();
    let cm = (estimate.translation - truth.translation).norm() * 100.0;
    (deg, cm)
}

/// Time spanned by the points' timestamps (s).
fn scan_duration(points: &[spacepose_geometry::Point]) -> f64 {
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.t), hi.max(p.t))
        });
    if hi >= lo { hi - lo } else { 0.0 }
}

fn score(estimator: &CnnEstimator, index: u64, f: &GeneratedFrame) -> CnnFrame {
    let truth = &f.truth.t_sensor_target;
    let syms = estimator.classes().symmetries();
    let mut row = CnnFrame {
        frame: index,
        range_m: truth.translation.norm(),
        points: f.points.len(),
        rate_deg_s: f.truth.w_target.norm().to_degrees(),
        scan_s: scan_duration(&f.points),
        raw_err_deg: f64::NAN,
        raw_err_cm: f64::NAN,
        err_deg: f64::NAN,
        err_cm: f64::NAN,
        success_raw: false,
        success_refined: false,
        f_conv_m2: f64::INFINITY,
        accepted: false,
        twins: spacepose_cnn::TwinOutcome::default(),
        top_probability: 0.0,
        hypothesis: 0,
        hypotheses_refined: 0,
        time_ms: spacepose_cnn::Timings::default(),
        fconv_ms: f64::NAN,
        error: None,
    };
    match estimator.estimate(&f.points) {
        Ok(e) => {
            (row.raw_err_deg, row.raw_err_cm) = errors(&e.t_sensor_target_raw, truth, syms);
            row.success_raw = row.raw_err_deg < SUCCESS_DEG && row.raw_err_cm < SUCCESS_CM;
            if e.refinement_error.is_none() {
                (row.err_deg, row.err_cm) = errors(&e.t_sensor_target, truth, syms);
                row.success_refined = row.err_deg < SUCCESS_DEG && row.err_cm < SUCCESS_CM;
            }
            row.f_conv_m2 = e.f_conv_m2;
            row.accepted = e.accepted;
            row.twins = e.twins;
            row.top_probability = e.top_probability;
            row.hypothesis = e.hypothesis;
            row.hypotheses_refined = e.hypotheses_refined;
            row.time_ms = e.time_ms;
            row.fconv_ms = e.fconv_ms;
            row.error = e.refinement_error;
        }
        Err(e) => row.error = Some(e.to_string()),
    }
    row
}

/// Generates the held-out set and scores every estimate.
pub fn evaluate(args: &EvalCnnArgs) -> Result<CnnReport> {
    if TRAINING_SEEDS.contains(&args.seed) {
        bail!(
            "seed {} was used for training, validation or smoke tests ({TRAINING_SEEDS:?}): pick another",
            args.seed
        );
    }
    let target = load_target(&args.target, 1.0)?;
    let model = args
        .model
        .clone()
        .unwrap_or_else(|| PathBuf::from("services/core/cnn/models").join(target.name()));
    let mut config = EstimatorConfig::default();
    if let Some(f_max) = args.f_max {
        config.refinement.f_max_m2 = f_max;
    }
    if let Some(h) = args.hypotheses {
        config.hypotheses = h;
    }
    if let Some(max_points) = args.max_points {
        config.refinement.max_points = max_points;
    }
    if let Some(stages) = &args.ndt_stages {
        config.refinement.ndt_stages_m = if stages == "none" {
            Vec::new()
        } else {
            stages
                .split(',')
                .map(|s| s.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .with_context(|| format!("--ndt-stages {stages:?}"))?
        };
    }
    let estimator = CnnEstimator::load_with(&model, engine(args)?, target.clone(), config.clone())
        .with_context(|| format!("loading the CNN from {}", model.display()))?;
    let generator = Generator::new(
        target.clone(),
        DatasetConfig {
            seed: args.seed,
            count: args.count as usize,
            image_size: estimator.preprocess_config().image_size,
            roll_step_deg: config.roll_step_deg,
            min_points: DEFAULT_MIN_POINTS,
        },
    )?;
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = args.sim_threads {
        pool = pool.num_threads(t);
    }
    let pool = pool
        .build()
        .context("cannot start the simulation threads")?;
    let bar = progress_bar(args.count, "cnn");
    let mut frames = Vec::with_capacity(args.count as usize);
    for start in (0..args.count).step_by(CHUNK) {
        let end = (start + CHUNK as u64).min(args.count);
        let chunk: Vec<GeneratedFrame> = pool.install(|| {
            (start..end)
                .into_par_iter()
                .map(|i| generator.frame(i))
                .collect::<Result<_, _>>()
        })?;
        for (i, f) in (start..end).zip(&chunk) {
            frames.push(score(&estimator, i, f));
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    Ok(report(args, &estimator, &model, config, frames))
}

/// The summary of the scored `frames`.
fn report(
    args: &EvalCnnArgs,
    estimator: &CnnEstimator,
    model: &std::path::Path,
    config: EstimatorConfig,
    frames: Vec<CnnFrame>,
) -> CnnReport {
    let n = frames.len().max(1) as f64;
    CnnReport {
        target: args.target.clone(),
        model: model.display().to_string(),
        engine: estimator.engine().to_string(),
        seed: args.seed,
        count: frames.len(),
        success_rate_refined: rate(&frames, |r| r.success_refined),
        success_rate_raw: rate(&frames, |r| r.success_raw),
        ang_err_deg: raw_refined(&frames, |r| r.raw_err_deg, |r| r.err_deg),
        pos_err_cm: raw_refined(&frames, |r| r.raw_err_cm, |r| r.err_cm),
        time_ms: time_split(&frames),
        fconv: fconv_stats(&frames, estimator.f_max_m2()),
        by_range: range_bins(&frames),
        errors: count(&frames, |r| r.error.is_some()),
        other_hypothesis: count(&frames, |r| r.hypothesis > 0),
        several_hypotheses: count(&frames, |r| r.hypotheses_refined > 1),
        twins_refined: count(&frames, |r| r.twins.twins_refined > 0),
        twin_used: count(&frames, |r| r.twins.twin.is_some()),
        // An empty f64 sum is -0.0, which prints as "-0".
        mean_points: if frames.is_empty() {
            0.0
        } else {
            frames.iter().map(|r| r.points as f64).sum::<f64>() / n
        },
        config,
        frames,
    }
}

/// Frames for which `keep` holds.
fn count(frames: &[CnnFrame], keep: impl Fn(&CnnFrame) -> bool) -> usize {
    frames.iter().filter(|r| keep(r)).count()
}

/// Frames for which `keep` holds over all frames (over 1 when none).
fn rate(frames: &[CnnFrame], keep: impl Fn(&CnnFrame) -> bool) -> f64 {
    count(frames, keep) as f64 / frames.len().max(1) as f64
}

/// Mean ± std of `value` over the frames for which `keep` holds.
fn mean_std_over(
    frames: &[CnnFrame],
    keep: impl Fn(&CnnFrame) -> bool,
    value: impl Fn(&CnnFrame) -> f64,
) -> MeanStd {
    MeanStd::of(
        &frames
            .iter()
            .filter(|r| keep(r))
            .map(value)
            .collect::<Vec<_>>(),
    )
}

/// An error before refinement over the raw successes and after it over
/// the refined successes.
fn raw_refined(
    frames: &[CnnFrame],
    raw: impl Fn(&CnnFrame) -> f64,
    refined: impl Fn(&CnnFrame) -> f64,
) -> RawRefined {
    RawRefined {
        raw: mean_std_over(frames, |r| r.success_raw, raw),
        refined: mean_std_over(frames, |r| r.success_refined, refined),
    }
}

/// Table IV: the time split over the frames without an error.
fn time_split(frames: &[CnnFrame]) -> TimeSplit {
    let ok: Vec<&CnnFrame> = frames.iter().filter(|r| r.error.is_none()).collect();
    let time =
        |f: fn(&CnnFrame) -> f64| TimeStats::of(&ok.iter().map(|r| f(r)).collect::<Vec<_>>());
    TimeSplit {
        preprocess: time(|r| r.time_ms.preprocess),
        inference: time(|r| r.time_ms.inference),
        refinement: time(|r| r.time_ms.refinement),
        total: time(|r| r.time_ms.total),
    }
}

/// The finite f_CONV values of the refined successes (`success`) or
/// failures (`!success`).
fn fconv_values(frames: &[CnnFrame], success: bool) -> Vec<f64> {
    frames
        .iter()
        .filter(|r| r.success_refined == success && r.f_conv_m2.is_finite())
        .map(|r| r.f_conv_m2)
        .collect()
}

/// The acceptance check against the refined successes, with `f_max_m2`.
fn fconv_stats(frames: &[CnnFrame], f_max_m2: f64) -> FconvStats {
    let (s, f) = (fconv_values(frames, true), fconv_values(frames, false));
    FconvStats {
        f_max_m2,
        accepted_rate: rate(frames, |r| r.accepted),
        false_accepts: count(frames, |r| r.accepted && !r.success_refined),
        false_rejects: count(frames, |r| !r.accepted && r.success_refined),
        success_max_m2: s.iter().copied().fold(f64::NAN, f64::max),
        success_median_m2: median(&s),
        failure_min_m2: f.iter().copied().fold(f64::NAN, f64::min),
        failure_median_m2: median(&f),
    }
}

/// Success by range over 2.5-5, 5-10, 10-15 and 15-20 m (the first bin also
/// holds the frames closer than 2.5 m, the last those at 20 m or beyond).
fn range_bins(frames: &[CnnFrame]) -> Vec<RangeBin> {
    [2.5, 5.0, 10.0, 15.0, 20.0]
        .windows(2)
        .map(|w| range_bin(frames, w[0], w[1]))
        .collect()
}

/// Success of the frames in [`lo`, `hi`) (unbounded below when `lo` ≤
/// 2.5 m, above when `hi` ≥ 20 m).
fn range_bin(frames: &[CnnFrame], lo: f64, hi: f64) -> RangeBin {
    let bin: Vec<&CnnFrame> = frames
        .iter()
        .filter(|r| (r.range_m >= lo || lo <= 2.5) && (r.range_m < hi || hi >= 20.0))
        .collect();
    let k = bin.len().max(1) as f64;
    RangeBin {
        range_m: [lo, hi],
        frames: bin.len(),
        success_rate_refined: bin.iter().filter(|r| r.success_refined).count() as f64 / k,
        success_rate_raw: bin.iter().filter(|r| r.success_raw).count() as f64 / k,
    }
}

/// Prints Tables III and IV.
pub fn print(report: &CnnReport, frames: bool) {
    println!("{}", render::summary_line(report));
    println!(
        "\nTable III (success: < {SUCCESS_DEG}° with d_sym and < {SUCCESS_CM} cm; errors over the successes)"
    );
    print!("{}", render::table3(report).render());
    println!("\nTable IV (one thread)");
    print!("{}", render::table4(&report.time_ms).render());
    println!("\n{}", render::fconv_line(&report.fconv));
    print!("\n{}", render::range_table(&report.by_range).render());
    if frames {
        print!("\n{}", render::frames_table(&report.frames).render());
    }
}

/// Runs the command.
pub fn run(args: &EvalCnnArgs) -> Result<()> {
    let report = evaluate(args)?;
    print(&report, args.frames);
    if let Some(path) = &args.json {
        std::fs::write(path, serde_json::to_string_pretty(&report)?)
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame at `range_m`, refined successfully when `success`.
    fn frame_at(range_m: f64, success: bool) -> CnnFrame {
        CnnFrame {
            frame: 0,
            range_m,
            points: 1000,
            rate_deg_s: 0.0,
            scan_s: 0.1,
            raw_err_deg: 1.0,
            raw_err_cm: 1.0,
            err_deg: 1.0,
            err_cm: 1.0,
            success_raw: success,
            success_refined: success,
            f_conv_m2: 1e-4,
            accepted: true,
            twins: spacepose_cnn::TwinOutcome::default(),
            top_probability: 0.5,
            hypothesis: 0,
            hypotheses_refined: 1,
            time_ms: spacepose_cnn::Timings::default(),
            fconv_ms: 0.0,
            error: None,
        }
    }

    #[test]
    fn every_frame_falls_in_one_range_bin() {
        let ranges = [1.0, 2.5, 4.9, 5.0, 12.0, 19.9, 20.0, 30.0];
        let frames: Vec<CnnFrame> = ranges.iter().map(|&r| frame_at(r, r < 10.0)).collect();
        let bins = range_bins(&frames);
        let counts: Vec<usize> = bins.iter().map(|b| b.frames).collect();
        assert_eq!(counts, [3, 1, 1, 3]);
        assert_eq!(bins.iter().map(|b| b.frames).sum::<usize>(), ranges.len());
        assert_eq!(bins[0].success_rate_refined, 1.0);
        assert_eq!(bins[3].success_rate_refined, 0.0);
    }
}
