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

pub mod acquisition;
mod args;
pub mod bounds;
pub mod crop_score;
pub mod deployed;
pub mod filter_score;
pub mod frames;
pub mod monte_carlo;
pub mod nees;
mod plot;
mod render;
pub mod report;
mod setup;

pub use args::{EvalInit, EvalTrackingArgs, Modes};
pub use deployed::{Answer, DeployedSuite, SuiteConfigs};
pub use report::{DIVERGED_DEG, DIVERGED_M, FrameRecord, ModeReport, TrackingReport};
pub use setup::{EvalConfig, Setup, frame_source};

use crate::common::{load_target, progress_bar};
use crate::stats::MeanMax;
use anyhow::{Context, Result, bail};
use nalgebra::Rotation3;
use spacepose_init_node::{InitServiceConfig, MethodKind};
use spacepose_lidar_sim::FrameSource;
use spacepose_lidar_sim_node::wire::{cloud_header, truth_acquisition};
use spacepose_messages::Name;
use spacepose_scenario::ScenarioKind;
use spacepose_tracker::TrackerConfig;
use std::path::Path;

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
    let tracked = run_frames(config, &source, frames, &mut suites, target.symmetries())?;
    Ok(tracked.report(config, source.scenario().name(), target.name(), frames))
}

/// What the frame loop collects: the records of each suite, and the
/// per-frame inputs shared by every mode.
struct Tracked {
    records: Vec<Vec<FrameRecord>>,
    points_total: usize,
    lags: Vec<f64>,
}

/// Simulates the frames in batches and runs every suite on each, behind a
/// progress bar; the first frame's truth acquisition starts every suite,
/// unless they acquire (`config.init`): then init's acquisitions are
/// scored, and the errors use d_sym over the target's `symmetries`.
fn run_frames(
    config: &EvalConfig,
    source: &FrameSource,
    frames: usize,
    suites: &mut [DeployedSuite],
    symmetries: &[Rotation3<f64>],
) -> Result<Tracked> {
    let symmetries = if config.init.is_some() {
        symmetries
    } else {
        &[]
    };
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
            if start + offset == 0 && config.init.is_none() {
                suites
                    .iter_mut()
                    .for_each(|s| s.acquire(truth_acquisition(frame, sensor)));
            }
            let lag = frames::blur_lag_deg(source.scenario(), frame);
            tracked.points_total += frame.points.len();
            tracked.lags.push(lag);
            for (suite, out) in suites.iter_mut().zip(tracked.records.iter_mut()) {
                let answer = suite.track(cloud_header(k, frame, 0), frame.points.clone())?;
                let output = answer.output.as_ref();
                let mut r = report::record(frame, k as usize, &answer.estimate, output, symmetries);
                r.blur_lag_deg = lag;
                r.crop = crop_score::CropKinds::of_sent(frame, &answer.sent);
                report::score_filter(&mut r, frame, answer.filter_state.as_ref(), symmetries);
                r.acquisition = answer.acquisitions.last().map(|a| {
                    let truth = &frame.truth.t_sensor_target;
                    acquisition::score(k, a, Some(truth), symmetries)
                });
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
            clutter: config.clutter,
            mismatch: config.mismatch.is_some(),
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
    let mut configuration = args.tracker_config.as_ref().map_or_else(
        || "defaults".to_string(),
        |p| format!("tracker config {}", p.display()),
    );
    if args.init == EvalInit::Acquire {
        configuration += ", acquired by init";
    }
    if args.clutter {
        configuration += ", facility clutter";
    }
    if let Some(sep) = args.echo_separation_m {
        configuration += &format!(", echo separation {sep} m");
    }
    if let Some(t) = args.integration_time_s {
        configuration += &format!(", {t} s integration");
    }
    if args.mismatch {
        configuration += ", model mismatch";
    }
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
        clutter: args.clutter,
        echo_separation_m: args.echo_separation_m,
        integration_time_s: args.integration_time_s,
        mismatch: args.mismatch.then(spacepose_lidar_sim::Mismatch::default),
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
        init: match args.init {
            EvalInit::Truth => None,
            EvalInit::Acquire => Some(InitServiceConfig {
                methods: vec![MethodKind::Cnn, MethodKind::TemplateMatching],
                ..InitServiceConfig::default()
            }),
        },
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
