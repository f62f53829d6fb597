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
    /// Evaluate an estimator against ground truth.
    #[command(subcommand)]
    Eval(EvalCommand),
}

/// Evaluations.
#[derive(Debug, Subcommand)]
pub enum EvalCommand {
    /// Tracking accuracy and speed per mode, as seed 000 Tables 2-3.
    Tracking(EvalTrackingArgs),
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
    /// Frames excluded from the "converged" statistics while the filter
    /// learns the angular velocity (seed 000 §5.2).
    #[arg(long, default_value_t = 10)]
    pub warmup: usize,
    /// Write the results as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Draw the errors over time (.png or .svg), like seed 000 Fig. 9/11.
    #[arg(long)]
    pub plot: Option<PathBuf>,
}
