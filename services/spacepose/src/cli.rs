//! Command-line definitions (clap).

use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;

/// Lidar pose acquisition and tracking of an uncooperative spacecraft.
#[derive(Debug, Parser)]
#[command(name = "spacepose", version, about)]
pub struct Cli {
    /// Log progress at info level (RUST_LOG overrides).
    #[arg(short, long, global = true)]
    pub verbose: bool,
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Sub-commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate lidar frames of a scenario and write them with ground truth.
    Sim(SimArgs),
    /// Generate the synthetic CNN training set (depth images, soft labels) as .npy files.
    Dataset(crate::dataset_cmd::DatasetArgs),
    /// Evaluate an estimator against ground truth.
    #[command(subcommand)]
    Eval(EvalCommand),
    /// Start the services of a deployment descriptor and wait for their
    /// health; a supervisor process stays behind (restarts, swaps, status).
    Up(UpArgs),
    /// The supervisor `spacepose up` leaves running (internal).
    #[command(hide = true)]
    Supervise(UpArgs),
    /// Swap an estimator of a running deployment: start the new instance,
    /// warm it from the filter state, switch the primary at a frame
    /// boundary, stop the old one.
    Swap(SwapArgs),
    /// Show the instances of running deployments.
    Status(PrefixArgs),
    /// Stop a deployment (SIGTERM, then SIGKILL) and clean up after it.
    Down(PrefixArgs),
    /// The main job: a simulated tumbling rendezvous through the real service
    /// processes, scored against truth.
    Demo(DemoArgs),
    /// Ground tool: telemetry over zenoh as a live table, optionally recorded.
    Ground(GroundArgs),
    /// Derive thresholds from simulated runs.
    #[command(subcommand)]
    Calibrate(crate::calibrate::CalibrateCommand),
}

/// zenoh endpoint overrides of a descriptor.
#[derive(Debug, Clone, Args)]
pub struct ZenohOverrideArgs {
    /// Deployment prefix (replaces the descriptor's).
    #[arg(long)]
    pub prefix: Option<String>,
    /// zenoh endpoint the suite listens on (replaces the descriptor's; repeatable).
    #[arg(long)]
    pub listen: Vec<String>,
    /// zenoh endpoint the suite connects to, e.g. a ground tool listening (repeatable).
    #[arg(long)]
    pub connect: Vec<String>,
}

/// `spacepose up`.
#[derive(Debug, Args)]
pub struct UpArgs {
    /// Deployment descriptor (TOML), e.g. deploy/demo.toml.
    pub deploy: PathBuf,
    /// Start only this host's part of a partitioned descriptor (its
    /// services and its bridge, under the host's local prefix), e.g.
    /// `--host b` with deploy/partitioned.toml.
    #[arg(long)]
    pub host: Option<String>,
    /// Overrides.
    #[command(flatten)]
    pub overrides: ZenohOverrideArgs,
}

/// `spacepose swap`.
#[derive(Debug, Args)]
pub struct SwapArgs {
    /// Kind of service to swap (`tracker`).
    pub kind: String,
    /// New tracking mode (ndt, deblur, ct-ndt, icp).
    #[arg(long)]
    pub mode: Option<String>,
    /// New binary (e.g. a new build of spacepose-tracker).
    #[arg(long)]
    pub binary: Option<PathBuf>,
    /// Deployment prefix (default: the only one running).
    #[arg(long)]
    pub prefix: Option<String>,
    /// How long to wait for the swap to finish (s).
    #[arg(long, default_value_t = 90.0)]
    pub timeout_s: f64,
}

/// `spacepose status` / `spacepose down`.
#[derive(Debug, Args)]
pub struct PrefixArgs {
    /// Deployment prefix (default: every deployment for status, the only one for down).
    #[arg(long)]
    pub prefix: Option<String>,
}

/// `spacepose demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Deployment descriptor.
    #[arg(long, default_value = "deploy/demo.toml")]
    pub deploy: PathBuf,
    /// Frames to run (lidar-sim's frame count).
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u64).range(1..))]
    pub frames: u64,
    /// Frames excluded from the converged error figures (filter warm-up).
    #[arg(long, default_value_t = 10)]
    pub warmup: usize,
    /// Write the summary as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Seconds to wait for missing poses once the sensor stops.
    #[arg(long, default_value_t = 5.0)]
    pub linger_s: f64,
    /// Inject a fault: `kill:NAME@K` (SIGKILL) or `stop:NAME@K` (SIGSTOP,
    /// a freeze) once frame K is published (repeatable).
    #[arg(long)]
    pub chaos: Vec<String>,
    /// Swap the primary tracker during the run: `MODE@K` (e.g. `ct-ndt@5`).
    #[arg(long)]
    pub swap: Option<String>,
    /// Overrides (default prefix: a fresh random one).
    #[command(flatten)]
    pub overrides: ZenohOverrideArgs,
}

/// `spacepose ground`.
#[derive(Debug, Args)]
pub struct GroundArgs {
    /// zenoh endpoint of a suite (repeatable; retried until it answers).
    #[arg(long)]
    pub connect: Vec<String>,
    /// Listen on this endpoint instead, for suites that connect to the ground (repeatable).
    #[arg(long)]
    pub listen: Vec<String>,
    /// Deployment prefix; `*` = every deployment.
    #[arg(long, default_value = "*")]
    pub prefix: String,
    /// Append every received message to this file as JSON lines.
    #[arg(long)]
    pub record: Option<PathBuf>,
    /// Stop after this many seconds.
    #[arg(long)]
    pub duration: Option<f64>,
    /// Stop after this many pose messages (exit 1 if --duration ends first).
    #[arg(long)]
    pub count: Option<u64>,
    /// Table refresh period in seconds (0 = only the final table).
    #[arg(long, default_value_t = 1.0)]
    pub refresh_s: f64,
}

/// Evaluations.
#[derive(Debug, Subcommand)]
pub enum EvalCommand {
    /// Tracking accuracy and speed per mode, as seed 000 Tables 2-3.
    Tracking(EvalTrackingArgs),
    /// CNN pose estimation + NDT refinement (seed 004 Tables III-IV) on held-out frames.
    Cnn(crate::eval::cnn::EvalCnnArgs),
    /// Template-matching acquisition (seed 002 §4): success rate, time, f_CONV.
    Tm(crate::eval::tm::EvalTmArgs),
}

/// Scenario names accepted on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ScenarioArg {
    /// Inspection and approach, 1°/s spin (seed 000 §4.3).
    SlowSpin,
    /// Same approach, 10°/s torque-free tumbling (seed 000 §4.4).
    Tumbling,
    /// Safety ellipse at 25-53 m, one frame every 50 s (seed 002 §4.3).
    Ellipse,
    /// Uniform random attitudes at a fixed range (seed 002 §4.3).
    Random,
}

impl ScenarioArg {
    /// The scenario crate's kind.
    pub fn kind(self) -> spacepose_scenario::ScenarioKind {
        use spacepose_scenario::ScenarioKind as K;
        match self {
            Self::SlowSpin => K::SlowSpin,
            Self::Tumbling => K::Tumbling,
            Self::Ellipse => K::Ellipse,
            Self::Random => K::Random,
        }
    }
}

/// Scan patterns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PatternArg {
    /// Livox Mid-40 rosette, 38.4° circular field of view (seed 004).
    Rosette,
    /// 40°×40° raster at 1° (seed 002 §4.1).
    Raster,
}

/// Output formats of simulated frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FormatArg {
    /// Binary PCD.
    Pcd,
    /// ASCII PCD.
    PcdAscii,
    /// Binary little-endian PLY.
    Ply,
}

/// `spacepose sim`.
#[derive(Debug, Args)]
pub struct SimArgs {
    /// Built-in target (`deos`, `envisat`) or a mesh file (STL, OBJ, PLY).
    #[arg(long, default_value = "deos")]
    pub target: String,
    /// Scale applied to a mesh file's coordinates (to metres).
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// Relative-motion scenario.
    #[arg(long, value_enum, default_value = "tumbling")]
    pub scenario: ScenarioArg,
    /// Number of frames to simulate.
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u64).range(1..))]
    pub frames: u64,
    /// Seed of every random draw (scenario and sensor).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Time compression of the chaser trajectory (>= 1), to cover a whole
    /// approach in few frames; the target's rotation keeps its true rate.
    #[arg(long, default_value_t = 1.0)]
    pub compression: f64,
    /// Range of the random scenario (m).
    #[arg(long, default_value_t = 20.0)]
    pub range: f64,
    /// Scan pattern.
    #[arg(long, value_enum, default_value = "rosette")]
    pub pattern: PatternArg,
    /// Integration time per frame (s); default: the sensor's (0.4 s for the
    /// rosette, ~10k points on deos at 10 m).
    #[arg(long)]
    pub integration_time: Option<f64>,
    /// Add the test-facility background (floor, wall, robot arm).
    #[arg(long)]
    pub clutter: bool,
    /// Ideal sensor: no noise, divergence, reflections, outliers, detection
    /// losses or motion blur.
    #[arg(long)]
    pub ideal: bool,
    /// File format of the frames.
    #[arg(long, value_enum, default_value = "pcd")]
    pub format: FormatArg,
}

/// Modes accepted by `eval tracking`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ModeArg {
    /// Smoothed NDT, previous pose as guess.
    Ndt,
    /// NDT with filter prediction and motion compensation.
    Deblur,
    /// Continuous-time NDT with filter prediction.
    CtNdt,
    /// Point-to-point ICP, previous pose as guess.
    Icp,
    /// All four.
    All,
}

/// `spacepose eval tracking`.
#[derive(Debug, Args)]
pub struct EvalTrackingArgs {
    /// Scenario (slow-spin or tumbling).
    #[arg(long, value_enum, default_value = "tumbling")]
    pub scenario: ScenarioArg,
    /// Tracking mode, or all of them on the same frames.
    #[arg(long, value_enum, default_value = "all")]
    pub mode: ModeArg,
    /// Frames to run; default: the whole scenario at 1 Hz.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub frames: Option<u64>,
    /// Seed of the scenario and the sensor. Seed 1 was used to tune the
    /// tracker: evaluate on any other.
    #[arg(long, default_value_t = 7)]
    pub seed: u64,
    /// Time compression of the chaser trajectory (>= 1).
    #[arg(long, default_value_t = 1.0)]
    pub compression: f64,
    /// Built-in target or mesh file.
    #[arg(long, default_value = "deos")]
    pub target: String,
    /// Scale applied to a mesh file's coordinates.
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// First frame of the scenario to run (the trackers start on the truth
    /// at that frame's scan start).
    #[arg(long, default_value_t = 0)]
    pub first_frame: usize,
    /// Frames excluded from the "converged" statistics while the filter
    /// learns the angular velocity (seed 000 §5.2).
    #[arg(long, default_value_t = 10)]
    pub warmup: usize,
    /// NDT degeneracy handling: rotations with a smaller lever arm are
    /// held at the prediction (`NdtParams::min_lever_arm_m`, m; 0 = the
    /// paper), in every mode (`ndt` mode has its own default,
    /// `TrackerConfig::ndt_mode_min_lever_arm_m`). Default: the tracker's.
    #[arg(long)]
    pub min_lever_arm_m: Option<f64>,
    /// Point noise (m) of the geometric measurement covariance fed to the
    /// filter (`TrackerConfig::geometric_sigma_m`; 0 = NDT's information).
    /// Default: the tracker's.
    #[arg(long)]
    pub geometric_sigma_m: Option<f64>,
    /// Tracker configuration (TOML, the `[tracker]` table's fields of a
    /// tracker service config, i.e. `TrackerConfig`) to start from instead
    /// of the defaults; the mode is set per evaluated mode and the flags
    /// below override it.
    #[arg(long)]
    pub tracker_config: Option<PathBuf>,
    /// Start pose of the ct-ndt scan. Default: the tracker's (filter-prior).
    #[arg(long, value_enum)]
    pub ct_start: Option<CtStartArg>,
    /// Write the results as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Draw the errors over time (.png or .svg), like seed 000 Fig. 9/11.
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

/// `--ct-start` values (`spacepose_tracker::CtStart`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CtStartArg {
    /// Seed 000 Eq. (14): the start pose fixed at the previous result.
    Fixed,
    /// The start pose optimised too, under the filter's estimate as prior.
    FilterPrior,
}

impl From<CtStartArg> for spacepose_tracker::CtStart {
    fn from(a: CtStartArg) -> Self {
        match a {
            CtStartArg::Fixed => Self::Fixed,
            CtStartArg::FilterPrior => Self::FilterPrior,
        }
    }
}
