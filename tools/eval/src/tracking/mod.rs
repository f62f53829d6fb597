//! `spacepose eval tracking`: the four tracking modes on a simulated
//! rendezvous, scored against ground truth as in seed 000 Tables 2-3 and
//! Fig. 9/11, through the deployed frame path.
//!
//! Conditions, chosen to match the paper's experiments (seed 000 §4.1,
//! §4.3-4.4):
//! - the suite's simulated sensor (Livox Mid-40 with every sensor effect
//!   on: noise, line-of-sight error, outliers, detection losses, beam
//!   divergence, reflections, motion blur); no facility clutter;
//! - 1 Hz frames with an integration time of 1 s (the sensor scans
//!   continuously): the paper's 8,000-70,000 raw points per cloud;
//! - each mode runs in its own copy of the suite's ingest, tracker and
//!   filter nodes ([`deployed`]), started by the sensor's truth acquisition
//!   of the first frame (`truth_init`), as a deployment with
//!   `truth_init = true` starts: the first frame refines that pose, and the
//!   track restarts at its end with zero rates;
//! - all modes see the same frames; frames are simulated in parallel
//!   beforehand, then each suite runs alone (the time per frame is the
//!   tracker's, voxel filter and motion compensation included);
//! - the error is the angle of the rotation between the published estimate
//!   and the truth (d of seed 004 Eq. 12; a symmetric flip counts when
//!   tracking) and the distance between their centres of mass.

mod args;
pub mod deployed;
pub mod frames;
pub mod monte_carlo;
mod plot;
mod render;
pub mod report;

pub use args::{EvalTrackingArgs, Modes};
pub use deployed::{Answer, DeployedSuite, SuiteConfigs};
pub use report::{DIVERGED_DEG, DIVERGED_M, FrameRecord, ModeReport, TrackingReport};

use crate::common::{load_target, progress_bar};
use crate::stats::MeanMax;
use anyhow::{Context, Result, bail};
use spacepose_ingest_node::IngestServiceConfig;
use spacepose_lidar_sim::FrameSource;
use spacepose_lidar_sim_node::LidarSimConfig;
use spacepose_lidar_sim_node::wire::{cloud_header, truth_acquisition};
use spacepose_messages::Name;
use spacepose_scenario::ScenarioKind;
use spacepose_tracker::{TrackerConfig, TrackingMode, TrackingModel};
use spacepose_tracker_node::TrackerServiceConfig;
use std::path::Path;

/// What to evaluate (the library form of the command-line arguments).
#[derive(Debug, Clone)]
pub struct EvalConfig {
    /// Scenario.
    pub scenario: ScenarioKind,
    /// Modes to run on the same frames.
    pub modes: Vec<TrackingMode>,
    /// Frames (None: the whole scenario).
    pub frames: Option<usize>,
    /// Seed of the scenario and the sensor.
    pub seed: u64,
    /// Chaser-trajectory compression.
    pub compression: f64,
    /// First frame to run; the truth acquisition is that frame's.
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
    /// Ingest's configuration (default: the service's, on this target, whose
    /// package gives the crop region).
    pub ingest: Option<IngestServiceConfig>,
}

impl EvalConfig {
    /// `modes` on `scenario` with `target` (name or path, scale), with the
    /// command line's defaults for the rest: the whole scenario, seed 1,
    /// no compression, from the first frame, 10 warm-up frames, the
    /// services' default configurations.
    pub fn new(target: (String, f64), scenario: ScenarioKind, modes: Vec<TrackingMode>) -> Self {
        EvalConfig {
            scenario,
            modes,
            frames: None,
            seed: 1,
            compression: 1.0,
            first_frame: 0,
            target,
            warmup: 10,
            min_lever_arm_m: None,
            geometric_sigma_m: None,
            ct_start: None,
            tracker: None,
            ingest: None,
        }
    }
}

/// Runs the evaluation.
pub fn evaluate(config: &EvalConfig) -> Result<TrackingReport> {
    if !matches!(
        config.scenario,
        ScenarioKind::SlowSpin | ScenarioKind::Tumbling
    ) {
        bail!("tracking is evaluated on slow-spin or tumbling (seed 000 §4.3-4.4)");
    }
    let target = load_target(&config.target.0, config.target.1)?;
    let source = frame_source(config)?;
    let total = source.scenario().natural_frame_count();
    let frames = config
        .frames
        .unwrap_or(total.saturating_sub(config.first_frame));
    if frames == 0 {
        bail!(
            "no frame to run (the scenario has {total} frames, first frame {})",
            config.first_frame
        );
    }
    let setup = Setup::new(config)?;
    let mut suites = setup.suites()?;
    let tracked = run_frames(config, &source, frames, &mut suites)?;
    Ok(tracked.report(config, source.scenario().name(), target.name(), frames))
}

/// The suites of an evaluation, one per mode, before any frame: their
/// configurations and the tracker's model (built once, as each tracker
/// service builds it from its config). The Criterion benchmark
/// `tracking_cost` starts its suites from it too.
pub struct Setup {
    /// Per mode of the evaluation, the suite's configurations.
    pub configs: Vec<SuiteConfigs>,
    /// The tracker's model of the target.
    pub model: TrackingModel,
}

impl Setup {
    /// The setup of `config`'s modes on its target.
    pub fn new(config: &EvalConfig) -> Result<Setup> {
        let base = suite_configs(config)?;
        let (model, _) = base.tracker.build_model().context("building the NDT map")?;
        let configs = config
            .modes
            .iter()
            .map(|&mode| {
                let mut c = base.clone();
                c.tracker.tracker.mode = mode;
                c
            })
            .collect();
        Ok(Setup { configs, model })
    }

    /// Fresh suites, one per mode.
    pub fn suites(&self) -> Result<Vec<DeployedSuite>> {
        self.configs
            .iter()
            .map(|c| DeployedSuite::new(c, self.model.clone()))
            .collect()
    }
}

/// The sensor's frames for `config` (the simulated sensor's own source).
pub fn frame_source(config: &EvalConfig) -> Result<FrameSource> {
    let sensor = LidarSimConfig {
        target: config.target.0.clone(),
        scale: config.target.1,
        scenario: config.scenario,
        seed: config.seed,
        compression: config.compression,
        ..LidarSimConfig::default()
    };
    // One frame period of integration: 1 s at the scenarios' 1 Hz.
    let period = sensor.frame_source()?.scenario().frame_period_s();
    frames::sensor_config(sensor, period).frame_source()
}

/// The services' configurations: the defaults, the target's crop, and the
/// tracker options of `config` (the mode is set per suite).
fn suite_configs(config: &EvalConfig) -> Result<SuiteConfigs> {
    let mut tracker = config.tracker.clone().unwrap_or_default();
    if let Some(lever) = config.min_lever_arm_m {
        tracker.ndt.min_lever_arm_m = lever;
        tracker.ndt_mode_min_lever_arm_m = lever;
    }
    if let Some(sigma) = config.geometric_sigma_m {
        tracker.geometric_sigma_m = sigma;
    }
    if let Some(start) = config.ct_start {
        tracker.ct_start = start;
    }
    let ingest = config
        .ingest
        .clone()
        .unwrap_or_else(|| IngestServiceConfig {
            target: config.target.0.clone(),
            target_scale: config.target.1,
            ..IngestServiceConfig::default()
        });
    Ok(SuiteConfigs {
        ingest,
        tracker: TrackerServiceConfig {
            target: config.target.0.clone(),
            target_scale: config.target.1,
            tracker,
            ..TrackerServiceConfig::default()
        },
        filter: Default::default(),
    })
}

/// What the frame loop collects: the records of each suite, and the
/// per-frame inputs shared by every mode.
struct Tracked {
    records: Vec<Vec<FrameRecord>>,
    points_total: usize,
    lags: Vec<f64>,
}

/// Simulates the frames in batches and runs every suite on each, behind a
/// progress bar; the first frame's truth acquisition starts every suite.
fn run_frames(
    config: &EvalConfig,
    source: &FrameSource,
    frames: usize,
    suites: &mut [DeployedSuite],
) -> Result<Tracked> {
    let mut tracked = Tracked {
        records: vec![Vec::with_capacity(frames); suites.len()],
        points_total: 0,
        lags: Vec::with_capacity(frames),
    };
    let sensor = Name::new("lidar-sim")?;
    let bar = progress_bar(frames as u64, "tracking");
    let first = config.first_frame as u64;
    for start in (0..frames).step_by(frames::BATCH_FRAMES) {
        let count = frames::BATCH_FRAMES.min(frames - start);
        let batch = frames::simulate_batch(source, first + start as u64, count)?;
        for (offset, frame) in batch.iter().enumerate() {
            let k = first + (start + offset) as u64;
            if start + offset == 0 {
                suites
                    .iter_mut()
                    .for_each(|s| s.acquire(truth_acquisition(frame, sensor)));
            }
            let lag = frames::blur_lag_deg(source.scenario(), frame);
            tracked.points_total += frame.points.len();
            tracked.lags.push(lag);
            for (suite, out) in suites.iter_mut().zip(tracked.records.iter_mut()) {
                let answer = suite.track(cloud_header(k, frame, 0), frame.points.clone())?;
                let mut r =
                    report::record(frame, k as usize, &answer.estimate, answer.output.as_ref());
                r.blur_lag_deg = lag;
                out.push(r);
            }
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    Ok(tracked)
}

impl Tracked {
    /// The report of `frames` frames of `scenario` on `target`, one summary
    /// per configured mode.
    fn report(
        self,
        config: &EvalConfig,
        scenario: &str,
        target: &str,
        frames: usize,
    ) -> TrackingReport {
        let modes = config
            .modes
            .iter()
            .zip(self.records)
            .map(|(mode, series)| (mode.to_string(), report::summarise(series, config.warmup)))
            .collect();
        TrackingReport {
            scenario: scenario.to_string(),
            target: target.to_string(),
            seed: config.seed,
            frames,
            first_frame: config.first_frame,
            compression: config.compression,
            warmup: config.warmup,
            mean_points_in: self.points_total as f64 / frames as f64,
            blur_lag_deg: MeanMax::of(&self.lags),
            modes,
        }
    }
}

/// Runs the command.
pub fn run(args: &EvalTrackingArgs) -> Result<()> {
    let config = eval_config(args)?;
    if let Some(path) = &args.report {
        return run_report(args, &config, path);
    }
    let report = evaluate(&config)?;
    print!("{}", render::render(&report));
    if let Some(path) = &args.json {
        write_json(path, &report)?;
    }
    if let Some(path) = &args.plot {
        plot::write_plot(path, &report)?;
    }
    Ok(())
}

/// `--report`: the Monte-Carlo over `--seeds`, printed and written.
fn run_report(args: &EvalTrackingArgs, config: &EvalConfig, path: &Path) -> Result<()> {
    let seeds = crate::seeds::SeedLists::committed()?.scenario_seeds(&args.seeds)?;
    let configuration = args.tracker_config.as_ref().map_or_else(
        || "defaults".to_string(),
        |p| format!("tracker config {}", p.display()),
    );
    let evaluate_seed = |seed| {
        evaluate(&EvalConfig {
            seed,
            ..config.clone()
        })
    };
    let report = monte_carlo::monte_carlo(evaluate_seed, &args.seeds, &seeds, &configuration)?;
    print!("{}", render::render_monte_carlo(&report));
    let text = serde_json::to_string_pretty(&report).context("serialising the report")?;
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))?;
    println!("report written to {}", path.display());
    Ok(())
}

/// The evaluation the command-line arguments ask for (reads the tracker
/// configuration file, if any).
fn eval_config(args: &EvalTrackingArgs) -> Result<EvalConfig> {
    Ok(EvalConfig {
        scenario: args.scenario,
        modes: args.mode.list(),
        frames: args.frames.map(|f| f as usize),
        seed: args.seed,
        compression: args.compression,
        first_frame: args.first_frame,
        target: (args.target.clone(), args.scale),
        warmup: args.warmup,
        min_lever_arm_m: args.min_lever_arm_m,
        geometric_sigma_m: args.geometric_sigma_m,
        ct_start: args.ct_start,
        tracker: args
            .tracker_config
            .as_deref()
            .map(load_tracker_config)
            .transpose()?,
        ingest: None,
    })
}

/// Writes `report` as pretty-printed JSON to `path` and says so.
fn write_json(path: &Path, report: &TrackingReport) -> Result<()> {
    let text = serde_json::to_string_pretty(report).context("serialising the report")?;
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))?;
    println!("results written to {}", path.display());
    Ok(())
}

/// Reads a `TrackerConfig` from a TOML file.
fn load_tracker_config(path: &Path) -> Result<TrackerConfig> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading tracker config {}", path.display()))?;
    let config: TrackerConfig =
        toml::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    config
        .validate()
        .with_context(|| format!("validating {}", path.display()))?;
    Ok(config)
}
