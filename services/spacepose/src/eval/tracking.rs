//! `spacepose eval tracking`: the four tracking modes on a simulated
//! rendezvous, scored against ground truth as in seed 000 Tables 2-3 and
//! Fig. 9/11.
//!
//! Conditions, chosen to match the paper's experiments (seed 000 §4.1,
//! §4.3-4.4):
//! - Livox Mid-40 model with every sensor effect on (noise, line-of-sight
//!   error, outliers, detection losses, beam divergence, reflections, motion
//!   blur); no facility clutter, since the paper crops it before tracking.
//! - 1 Hz frames with an integration time of 1 s (the sensor scans
//!   continuously), which gives the paper's 8,000-70,000 raw points per
//!   cloud over the approach.
//! - Every tracker starts from the true pose at the first scan start with
//!   zero velocity and angular velocity (the paper's truth initialisation).
//! - All modes see the same frames. Timing is single-threaded: frames are
//!   simulated in parallel beforehand, then each tracker runs alone.
//! - The error is the angle of the rotation between estimate and truth
//!   (d of seed 004 Eq. 12; a symmetric flip counts as an error when
//!   tracking) and the distance between estimated and true centre of mass.

use super::stats::{MeanMax, median};
use super::{tracking_plot, tracking_render};
use crate::cli::{EvalTrackingArgs, ModeArg, ScenarioArg};
use crate::common::load_target;
use crate::sim_cmd::progress_bar;
use anyhow::{Context, Result, bail};
use nalgebra::Vector3;
use rayon::prelude::*;
use serde::Serialize;
use spacepose_lidar_sim::{Frame, LidarSimulator, ReturnKind, SensorConfig};
use spacepose_registration::NdtMapParams;
use spacepose_scenario::{Scenario, ScenarioConfig, build};
use spacepose_target::Target;
use spacepose_tracker::{TrackStatus, Tracker, TrackerConfig, TrackingMode, TrackingModel};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

/// Spacing of the model cloud sampled from the target mesh (m).
pub const MODEL_SPACING_M: f64 = 0.015;
/// A frame whose error exceeds these has lost the target in truth, whatever
/// the tracker reports.
pub const DIVERGED_DEG: f64 = 10.0;
/// See [`DIVERGED_DEG`] (m).
pub const DIVERGED_M: f64 = 0.5;

/// What to evaluate (the library form of the command-line arguments).
#[derive(Debug, Clone)]
pub struct EvalConfig {
    /// Scenario.
    pub scenario: ScenarioArg,
    /// Modes to run on the same frames.
    pub modes: Vec<TrackingMode>,
    /// Frames (None: the whole scenario).
    pub frames: Option<usize>,
    /// Seed of the scenario and the sensor.
    pub seed: u64,
    /// Chaser-trajectory compression.
    pub compression: f64,
    /// First frame to run (frames before it are skipped, e.g. the fly-around
    /// of a compressed scenario).
    pub first_frame: usize,
    /// Target name or mesh path, and its scale.
    pub target: (String, f64),
    /// Frames excluded from the converged statistics.
    pub warmup: usize,
    /// Overrides the tracker's NDT `min_lever_arm_m` (and
    /// `ndt_mode_min_lever_arm_m`, its value in `ndt` mode).
    pub min_lever_arm_m: Option<f64>,
    /// Overrides the tracker's `geometric_sigma_m`.
    pub geometric_sigma_m: Option<f64>,
    /// Overrides the tracker's `ct_start`.
    pub ct_start: Option<spacepose_tracker::CtStart>,
    /// Base tracker configuration (the defaults when `None`).
    pub tracker: Option<TrackerConfig>,
}

/// One frame of one mode.
#[derive(Debug, Clone, Serialize)]
pub struct FrameRecord {
    /// Frame index within the scenario.
    pub frame: usize,
    /// Scan end (s).
    pub t: f64,
    /// Range to the target centre of mass (m).
    pub range_m: f64,
    /// Tracker status.
    pub status: TrackStatus,
    /// Angular error (deg); NaN when lost.
    pub ang_err_deg: f64,
    /// Position error (cm); NaN when lost.
    pub pos_err_cm: f64,
    /// Error of the filter's angular velocity after this frame, `|ω̂ − ω|`
    /// in the target frame (deg/s).
    pub w_err_deg_s: f64,
    /// Its component along the true ω (deg/s; for a spinning target, the
    /// spin-rate error that drifts an unobservable roll).
    pub w_err_along_deg_s: f64,
    /// Processing time, voxel filter included (ms).
    pub time_ms: f64,
    /// Registration iterations.
    pub iterations: usize,
    /// Mean registration cost per inlier (NDT: Mahalanobis; ICP: m²).
    pub cost_mean: f64,
    /// Fraction of the used points with a correspondence.
    pub inlier_fraction: f64,
    /// Directions left at the prediction as unobservable.
    pub degenerate_directions: usize,
    /// The weakest rotation's lever arm (m; NaN when not computed).
    pub weakest_lever_arm_m: f64,
    /// Raw points in the frame.
    pub points_in: usize,
    /// Points after pre-processing.
    pub points_used: usize,
    /// Why the frame is degraded or lost (empty when tracking).
    pub reason: String,
    /// Scan blur: the angle the true attitude turns between the mean time
    /// of the frame's target returns and the scan end (deg). A one-pose fit
    /// of the uncompensated cloud sees the target near its mean time, so
    /// `ndt` and `icp` modes lag the end-of-scan truth by about this much
    /// even when fully converged (see [`blur_lag_deg`]). The same in every
    /// mode.
    pub blur_lag_deg: f64,
    /// `ct-ndt` mode: CT-NDT stalled and the frame was fitted as `deblur`
    /// fits it (`TrackerConfig::ct_ndt_stall_fallback`).
    pub fallback: bool,
}

/// Summary of one mode (the columns of seed 000 Tables 2-3).
#[derive(Debug, Clone, Serialize)]
pub struct ModeReport {
    /// Angular error over frames with a pose (deg).
    pub ang_err_deg: MeanMax,
    /// Position error over frames with a pose (cm).
    pub pos_err_cm: MeanMax,
    /// Execution time (ms).
    pub time_ms: MeanMax,
    /// Median execution time (ms).
    pub time_ms_median: f64,
    /// Registration iterations.
    pub iterations: MeanMax,
    /// Angular error after the warm-up frames (deg).
    pub ang_err_deg_converged: MeanMax,
    /// Position error after the warm-up frames (cm).
    pub pos_err_cm_converged: MeanMax,
    /// Frames the tracker reported lost.
    pub lost_frames: usize,
    /// Frames the tracker reported degraded.
    pub degraded_frames: usize,
    /// Frames whose true error exceeded 10° or 50 cm (including lost ones).
    pub diverged_frames: usize,
    /// Frames fitted by the stall fallback (`ct-ndt` mode).
    pub fallback_frames: usize,
    /// Frames run.
    pub frames: usize,
    /// Per-frame records.
    pub series: Vec<FrameRecord>,
}

/// The whole evaluation.
#[derive(Debug, Clone, Serialize)]
pub struct TrackingReport {
    /// Scenario name.
    pub scenario: String,
    /// Target name.
    pub target: String,
    /// Seed.
    pub seed: u64,
    /// Frames run.
    pub frames: usize,
    /// First frame index.
    pub first_frame: usize,
    /// Chaser-trajectory compression.
    pub compression: f64,
    /// Warm-up frames excluded from the converged statistics.
    pub warmup: usize,
    /// Mean raw points per frame.
    pub mean_points_in: f64,
    /// Scan blur over the frames (deg; see [`FrameRecord::blur_lag_deg`]).
    pub blur_lag_deg: MeanMax,
    /// Results per mode name.
    pub modes: BTreeMap<String, ModeReport>,
}

/// Frames simulated together (in parallel) before the trackers see them.
const BATCH_FRAMES: usize = 8;

/// Runs the evaluation.
pub fn evaluate(config: &EvalConfig) -> Result<TrackingReport> {
    check_scenario(config.scenario)?;
    let target = load_target(&config.target.0, config.target.1)?;
    let model = build_model(&target)?;
    let scenario = build_scenario(config)?;
    let frames = frame_count(config, scenario.natural_frame_count())?;
    let simulator = build_simulator(&target, scenario.as_ref())?;
    let end_times: Vec<f64> =
        scenario.frame_end_times(config.first_frame + frames)[config.first_frame..].to_vec();
    let mut trackers = start_trackers(
        config,
        &model,
        scenario.as_ref(),
        end_times[0] - scenario.frame_period_s(),
    )?;
    let tracked = track_frames(
        config,
        &simulator,
        scenario.as_ref(),
        &end_times,
        &mut trackers,
    )?;
    Ok(report(
        config,
        scenario.name(),
        target.name(),
        frames,
        tracked,
    ))
}

/// Fails unless `scenario` is one the tracking evaluation runs on.
fn check_scenario(scenario: ScenarioArg) -> Result<()> {
    if !matches!(scenario, ScenarioArg::SlowSpin | ScenarioArg::Tumbling) {
        bail!("tracking is evaluated on slow-spin or tumbling (seed 000 §4.3-4.4)");
    }
    Ok(())
}

/// The trackers' model: the target's surface sampled every
/// [`MODEL_SPACING_M`] and its NDT map.
fn build_model(target: &Target) -> Result<TrackingModel> {
    let model_cloud = target.sample_surface(MODEL_SPACING_M, 0);
    TrackingModel::build(&model_cloud, &NdtMapParams::default()).context("building the NDT map")
}

/// The configured scenario, with the evaluation's seed and compression.
fn build_scenario(config: &EvalConfig) -> Result<Box<dyn Scenario>> {
    let mut scenario_config = ScenarioConfig::default_for(config.scenario.kind());
    scenario_config.seed = config.seed;
    scenario_config.compression = config.compression;
    build(&scenario_config).context("invalid scenario")
}

/// Frames to run: the configured count, or the rest of the scenario's
/// `total` frames from the first one. Fails when that is none.
fn frame_count(config: &EvalConfig, total: usize) -> Result<usize> {
    let frames = config
        .frames
        .unwrap_or(total.saturating_sub(config.first_frame));
    if frames == 0 {
        bail!(
            "no frame to run (the scenario has {total} frames, first frame {})",
            config.first_frame
        );
    }
    Ok(frames)
}

/// A Livox Mid-40 simulator of `target` integrating over one frame period
/// of `scenario`.
fn build_simulator(target: &Arc<Target>, scenario: &dyn Scenario) -> Result<LidarSimulator> {
    let mut sensor = SensorConfig::livox_mid40();
    sensor.integration_time_s = scenario.frame_period_s();
    LidarSimulator::new(target.clone(), sensor).context("building the simulator")
}

/// What the frame loop collects: the records of each tracker, in the order
/// of the trackers, and the per-frame inputs shared by every mode.
struct Tracked {
    /// Per-frame records, one series per tracker.
    records: Vec<Vec<FrameRecord>>,
    /// Raw points over all frames.
    points_total: usize,
    /// Scan blur of each frame (deg; see [`blur_lag_deg`]).
    lags: Vec<f64>,
}

/// Simulates the frames ending at `end_times` in batches of
/// [`BATCH_FRAMES`] and runs every tracker on each, behind a progress bar.
fn track_frames(
    config: &EvalConfig,
    simulator: &LidarSimulator,
    scenario: &dyn Scenario,
    end_times: &[f64],
    trackers: &mut [Tracker],
) -> Result<Tracked> {
    let frames = end_times.len();
    let mut tracked = Tracked {
        records: vec![Vec::with_capacity(frames); trackers.len()],
        points_total: 0,
        lags: Vec::with_capacity(frames),
    };
    let bar = progress_bar(frames as u64, "tracking");
    for (batch_index, batch) in end_times.chunks(BATCH_FRAMES).enumerate() {
        let first = config.first_frame + batch_index * BATCH_FRAMES;
        let simulated = simulate_batch(simulator, scenario, batch, first, config.seed)?;
        for (offset, frame) in simulated.iter().enumerate() {
            tracked.push_frame(scenario, frame, first + offset, trackers)?;
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    Ok(tracked)
}

impl Tracked {
    /// Counts the points and blur of `frame` (scenario frame `index`) and
    /// appends each tracker's record of it.
    fn push_frame(
        &mut self,
        scenario: &dyn Scenario,
        frame: &Frame,
        index: usize,
        trackers: &mut [Tracker],
    ) -> Result<()> {
        self.points_total += frame.points.len();
        let lag = blur_lag_deg(scenario, frame);
        self.lags.push(lag);
        for (tracker, out) in trackers.iter_mut().zip(self.records.iter_mut()) {
            let mut record = track_frame(tracker, frame, index)?;
            record.blur_lag_deg = lag;
            out.push(record);
        }
        Ok(())
    }
}

/// The report of `frames` frames of `scenario_name` on `target_name`, one
/// summary per configured mode.
fn report(
    config: &EvalConfig,
    scenario_name: &str,
    target_name: &str,
    frames: usize,
    tracked: Tracked,
) -> TrackingReport {
    let modes = config
        .modes
        .iter()
        .zip(tracked.records)
        .map(|(mode, series)| (mode.to_string(), summarise(series, config.warmup)))
        .collect();
    TrackingReport {
        scenario: scenario_name.to_string(),
        target: target_name.to_string(),
        seed: config.seed,
        frames,
        first_frame: config.first_frame,
        compression: config.compression,
        warmup: config.warmup,
        mean_points_in: tracked.points_total as f64 / frames as f64,
        blur_lag_deg: MeanMax::of(&tracked.lags),
        modes,
    }
}

/// One tracker per mode, initialised on the truth at `t0` with zero rates.
fn start_trackers(
    config: &EvalConfig,
    model: &TrackingModel,
    scenario: &dyn Scenario,
    t0: f64,
) -> Result<Vec<Tracker>> {
    let pose0 = scenario.pose_at(t0);
    config
        .modes
        .iter()
        .map(|&mode| {
            let mut tracker_config = TrackerConfig {
                mode,
                ..config.tracker.clone().unwrap_or_default()
            };
            if let Some(lever) = config.min_lever_arm_m {
                tracker_config.ndt.min_lever_arm_m = lever;
                tracker_config.ndt_mode_min_lever_arm_m = lever;
            }
            if let Some(sigma) = config.geometric_sigma_m {
                tracker_config.geometric_sigma_m = sigma;
            }
            if let Some(start) = config.ct_start {
                tracker_config.ct_start = start;
            }
            let mut tracker = Tracker::new(tracker_config, model.clone())?;
            tracker.initialize(t0, &pose0, Vector3::zeros(), Vector3::zeros())?;
            Ok(tracker)
        })
        .collect()
}

/// Simulates the frames ending at `end_times` in parallel, frame `first + i`
/// with its own random stream of `seed`.
fn simulate_batch(
    simulator: &LidarSimulator,
    scenario: &dyn Scenario,
    end_times: &[f64],
    first: usize,
    seed: u64,
) -> Result<Vec<Frame>> {
    end_times
        .par_iter()
        .enumerate()
        .map(|(i, &t)| {
            let mut rng = LidarSimulator::frame_rng(seed, (first + i) as u64);
            simulator
                .try_simulate(&scenario.state_at(t), &mut rng)
                .with_context(|| format!("simulating frame {}", first + i))
        })
        .collect()
}

/// The angle (deg) between the true attitude at the mean time of the
/// frame's target returns and at its end: the lag of a one-pose fit of the
/// blurred cloud. NaN for a frame without target returns.
pub fn blur_lag_deg(scenario: &dyn Scenario, frame: &Frame) -> f64 {
    let times: Vec<f64> = frame
        .points
        .iter()
        .zip(&frame.kinds)
        .filter(|(_, k)| **k == ReturnKind::Target)
        .map(|(p, _)| p.t)
        .collect();
    if times.is_empty() {
        return f64::NAN;
    }
    let t_mean = times.iter().sum::<f64>() / times.len() as f64;
    let (ang, _) = scenario
        .pose_at(t_mean)
        .error_to(&frame.truth.t_sensor_target);
    ang.to_degrees()
}

/// Runs `tracker` on `frame` (scenario frame `index`) and scores it
/// against the truth; `blur_lag_deg` is left NaN for the caller to set.
fn track_frame(tracker: &mut Tracker, frame: &Frame, index: usize) -> Result<FrameRecord> {
    let out = tracker
        .process(&frame.points, frame.scan_start, frame.scan_end)
        .with_context(|| format!("frame {index}"))?;
    let has_pose = out.status != TrackStatus::Lost;
    let (ang, pos) = out.t_sensor_target.error_to(&frame.truth.t_sensor_target);
    let w_err = out.w_target - frame.truth.w_target;
    Ok(FrameRecord {
        frame: index,
        t: frame.scan_end,
        range_m: frame.truth.t_sensor_target.translation.norm(),
        status: out.status,
        ang_err_deg: if has_pose { ang.to_degrees() } else { f64::NAN },
        pos_err_cm: if has_pose { pos * 100.0 } else { f64::NAN },
        w_err_deg_s: w_err.norm().to_degrees(),
        w_err_along_deg_s: w_err
            .dot(
                &frame
                    .truth
                    .w_target
                    .try_normalize(1e-12)
                    .unwrap_or_default(),
            )
            .to_degrees(),
        time_ms: out.timings.total_ms,
        iterations: out.iterations(),
        cost_mean: out.registration.as_ref().map_or(f64::NAN, |r| r.cost.mean),
        inlier_fraction: out
            .registration
            .as_ref()
            .map_or(f64::NAN, |r| r.inlier_fraction()),
        degenerate_directions: out
            .registration
            .as_ref()
            .map_or(0, |r| r.degenerate_directions),
        blur_lag_deg: f64::NAN,
        fallback: out.fallback,
        weakest_lever_arm_m: out
            .registration
            .as_ref()
            .map_or(f64::NAN, |r| r.weakest_lever_arm_m),
        points_in: out.points_in,
        points_used: out.points_used,
        reason: out.reason,
    })
}

/// The summary of one mode's per-frame records, `warmup` frames excluded
/// from the converged statistics.
fn summarise(series: Vec<FrameRecord>, warmup: usize) -> ModeReport {
    let pick = |f: fn(&FrameRecord) -> f64, skip: usize| -> Vec<f64> {
        series.iter().skip(skip).map(f).collect()
    };
    let count = |s: TrackStatus| series.iter().filter(|r| r.status == s).count();
    let diverged = series
        .iter()
        .filter(|r| !(r.ang_err_deg <= DIVERGED_DEG && r.pos_err_cm <= DIVERGED_M * 100.0))
        .count();
    let times = pick(|r| r.time_ms, 0);
    ModeReport {
        ang_err_deg: MeanMax::of(&pick(|r| r.ang_err_deg, 0)),
        pos_err_cm: MeanMax::of(&pick(|r| r.pos_err_cm, 0)),
        time_ms: MeanMax::of(&times),
        time_ms_median: median(&times),
        iterations: MeanMax::of(&pick(|r| r.iterations as f64, 0)),
        ang_err_deg_converged: MeanMax::of(&pick(|r| r.ang_err_deg, warmup)),
        pos_err_cm_converged: MeanMax::of(&pick(|r| r.pos_err_cm, warmup)),
        lost_frames: count(TrackStatus::Lost),
        degraded_frames: count(TrackStatus::Degraded),
        diverged_frames: diverged,
        fallback_frames: series.iter().filter(|r| r.fallback).count(),
        frames: series.len(),
        series,
    }
}

/// Runs the command.
pub fn run(args: &EvalTrackingArgs) -> Result<()> {
    let config = eval_config(args)?;
    let report = evaluate(&config)?;
    print!("{}", tracking_render::render(&report));
    if let Some(path) = &args.json {
        write_json(path, &report)?;
    }
    if let Some(path) = &args.plot {
        tracking_plot::write_plot(path, &report)?;
    }
    Ok(())
}

/// The evaluation the command-line arguments ask for (reads the tracker
/// configuration file, if any).
fn eval_config(args: &EvalTrackingArgs) -> Result<EvalConfig> {
    Ok(EvalConfig {
        scenario: args.scenario,
        modes: modes_of(args.mode),
        frames: args.frames.map(|f| f as usize),
        seed: args.seed,
        compression: args.compression,
        first_frame: args.first_frame,
        target: (args.target.clone(), args.scale),
        warmup: args.warmup,
        min_lever_arm_m: args.min_lever_arm_m,
        geometric_sigma_m: args.geometric_sigma_m,
        ct_start: args.ct_start.map(Into::into),
        tracker: args
            .tracker_config
            .as_deref()
            .map(load_tracker_config)
            .transpose()?,
    })
}

/// The tracking modes `mode` selects.
fn modes_of(mode: ModeArg) -> Vec<TrackingMode> {
    match mode {
        ModeArg::All => TrackingMode::ALL.to_vec(),
        ModeArg::Ndt => vec![TrackingMode::Ndt],
        ModeArg::Deblur => vec![TrackingMode::Deblur],
        ModeArg::CtNdt => vec![TrackingMode::CtNdt],
        ModeArg::Icp => vec![TrackingMode::Icp],
    }
}

/// Writes `report` as pretty-printed JSON to `path` and says so.
fn write_json(path: &PathBuf, report: &TrackingReport) -> Result<()> {
    let text = serde_json::to_string_pretty(report).context("serialising the report")?;
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))?;
    println!("results written to {}", path.display());
    Ok(())
}

/// Reads a `TrackerConfig` from a TOML file.
fn load_tracker_config(path: &std::path::Path) -> Result<TrackerConfig> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading tracker config {}", path.display()))?;
    let config: TrackerConfig =
        toml::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    config
        .validate()
        .with_context(|| format!("validating {}", path.display()))?;
    Ok(config)
}

#[cfg(test)]
mod tests {
    use super::*;
    use spacepose_geometry::Point;
    use spacepose_scenario::ScenarioKind;

    fn point_at(t: f64) -> Point {
        Point {
            x: 0.0,
            y: 0.0,
            z: 10.0,
            intensity: 1.0,
            t,
        }
    }

    #[test]
    fn blur_lag_is_the_turn_since_the_mean_target_return() {
        let scenario = build(&ScenarioConfig::default_for(ScenarioKind::Tumbling)).unwrap();
        let end = scenario.frame_end_times(5)[4];
        let mut frame = Frame {
            points: vec![point_at(end - 1.0), point_at(end), point_at(end - 1.0)],
            kinds: vec![ReturnKind::Target, ReturnKind::Target, ReturnKind::Clutter],
            scan_start: end - 1.0,
            scan_end: end,
            truth: scenario.state_at(end),
        };
        // The clutter return does not count: the mean time is end − 0.5 s.
        let lag = blur_lag_deg(scenario.as_ref(), &frame);
        let (expected, _) = scenario
            .pose_at(end - 0.5)
            .error_to(&frame.truth.t_sensor_target);
        assert!((lag - expected.to_degrees()).abs() < 1e-9, "{lag}");
        // Half a second of a 10°/s tumble (plus its precession).
        assert!((4.0..7.0).contains(&lag), "{lag}");
        frame.kinds = vec![ReturnKind::Outlier; 3];
        assert!(blur_lag_deg(scenario.as_ref(), &frame).is_nan());
    }
}
