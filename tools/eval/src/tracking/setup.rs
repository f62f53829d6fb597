//! What an evaluation runs: its configuration, the services' configurations
//! on the target, and the suites, one per mode, before any frame.

use super::deployed::{DeployedSuite, SuiteConfigs};
use super::frames;
use anyhow::{Context, Result};
use spacepose_filter_node::FilterServiceConfig;
use spacepose_ingest_node::IngestServiceConfig;
use spacepose_init_node::InitServiceConfig;
use spacepose_lidar_sim::FrameSource;
use spacepose_lidar_sim_node::LidarSimConfig;
use spacepose_scenario::ScenarioKind;
use spacepose_tracker::{TrackerConfig, TrackingMode, TrackingModel};
use spacepose_tracker_node::TrackerServiceConfig;

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
    /// The test facility's background (floor, back wall, robot arm) in the
    /// frames, which ingest must crop (issue 25 item 6); off in orbit.
    pub clutter: bool,
    /// The sensor's echo separation (m; `inf`: seed 004's average of every
    /// echo); `None`: the sensor's default.
    pub echo_separation_m: Option<f64>,
    /// The sensor's integration time per frame (s); `None`: the frame
    /// period (1 s: seed 000's continuous scanning).
    pub integration_time_s: Option<f64>,
    /// The world departs from the model (issue 25 item 3): the target as
    /// built and its own motion within the scans; the services keep the
    /// nominal package.
    pub mismatch: Option<spacepose_lidar_sim::Mismatch>,
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
    /// `None`: every suite starts from the sensor's truth acquisition of
    /// the first frame. `Some`: the init service acquires from the frames
    /// with this configuration (the deployed path from a no-truth start),
    /// and reacquires after a loss.
    pub init: Option<InitServiceConfig>,
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
            clutter: false,
            echo_separation_m: None,
            integration_time_s: None,
            mismatch: None,
            warmup: 10,
            min_lever_arm_m: None,
            geometric_sigma_m: None,
            ct_start: None,
            tracker: None,
            ingest: None,
            init: None,
        }
    }
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
    /// Init's configuration, when the suites acquire.
    pub init: Option<InitServiceConfig>,
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
        let init = config.init.clone().map(|mut init| {
            init.target = config.target.0.clone();
            init.target_scale = config.target.1;
            init
        });
        Ok(Setup {
            configs,
            model,
            init,
        })
    }

    /// Fresh suites, one per mode.
    pub fn suites(&self) -> Result<Vec<DeployedSuite>> {
        self.configs
            .iter()
            .map(|c| match &self.init {
                None => DeployedSuite::new(c, self.model.clone()),
                Some(init) => DeployedSuite::with_init(c, self.model.clone(), init.clone()),
            })
            .collect()
    }
}

/// The sensor's frames for `config` (the simulated sensor's own source).
pub fn frame_source(config: &EvalConfig) -> Result<FrameSource> {
    let defaults = LidarSimConfig::default();
    let sensor = LidarSimConfig {
        target: config.target.0.clone(),
        scale: config.target.1,
        scenario: config.scenario,
        seed: config.seed,
        compression: config.compression,
        echo_separation_m: config
            .echo_separation_m
            .unwrap_or(defaults.echo_separation_m),
        mismatch: config.mismatch.clone(),
        ..defaults
    };
    // One frame period of integration: 1 s at the scenarios' 1 Hz.
    let period = sensor.frame_source()?.scenario().frame_period_s();
    let integration = config.integration_time_s.unwrap_or(period);
    frames::sensor_config(sensor, integration, config.clutter).frame_source()
}

/// The services' configurations: the defaults, the target's crop, and the
/// tracker options of `config` (the mode is set per suite). The filter
/// service runs the tracker's filter configuration: the tracker restores
/// its local filter from the service every frame, so the two must be one
/// tuning (a `[filter]` section in `--tracker-config` reaches both).
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
    let filter = FilterServiceConfig {
        filter: tracker.filter.clone(),
        ..FilterServiceConfig::default()
    };
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
        filter,
    })
}
