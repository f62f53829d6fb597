//! Command-line definitions (clap).

use clap::{Args, Parser, Subcommand};
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
    Sim(spacepose_eval::sim::SimArgs),
    /// Generate the synthetic CNN training set (depth images, soft labels) as .npy files.
    Dataset(spacepose_eval::dataset::DatasetArgs),
    /// Train a CNN for a target package into its cnn/ directory (datasets,
    /// PyTorch training, export, check); needs tools/train/setup.sh.
    Train(spacepose_eval::train::TrainArgs),
    /// Track a recording (PCD/PLY directory, MCAP file, ROS 2 bag) with the
    /// suite's frame pipeline in one process, and write the poses.
    Track(spacepose_eval::track::TrackArgs),
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
    /// Replay a recorded run (`--record RUN.mcap`) through the suite and
    /// compare the poses with the recorded ones.
    Replay(ReplayArgs),
    /// Ground tool: telemetry over zenoh as a live table, optionally recorded.
    Ground(GroundArgs),
    /// Target packages: prepare a mesh into one, or show one.
    #[command(subcommand)]
    Target(spacepose_eval::target::TargetCommand),
    /// Derive thresholds from simulated runs.
    #[command(subcommand)]
    Calibrate(spacepose_eval::calibrate::CalibrateCommand),
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
    /// Record the run into this MCAP file (Foxglove schemas: clouds,
    /// poses, filter states, acquisitions, health, truth, the target
    /// model, the descriptor); docs/recording.md.
    #[arg(long, value_name = "RUN.mcap")]
    pub record: Option<PathBuf>,
    /// Serve the run live to Foxglove: a Foxglove WebSocket server on this
    /// loopback address (default 127.0.0.1:8765); docs/recording.md.
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "127.0.0.1:8765")]
    pub view: Option<std::net::SocketAddr>,
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
    /// Run on this target instead of the descriptor's: a package directory,
    /// a built-in name, a mesh file (prepared on first use) or `zoo:N`.
    /// Every service takes its numbers from the package, and the sensor's
    /// legs are moved out until the whole target is in view.
    #[arg(long)]
    pub target: Option<String>,
    /// Seed of the simulated sensor's scenario and noise (replaces the
    /// descriptor's).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Scale of a mesh file given to --target (0.001 for millimetres).
    #[arg(long, default_value_t = 1.0, requires = "target")]
    pub scale: f64,
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
    /// Record the run into this MCAP file (Foxglove schemas, truth
    /// included); docs/recording.md.
    #[arg(long, value_name = "RUN.mcap")]
    pub record: Option<PathBuf>,
    /// Serve the run live to Foxglove: a Foxglove WebSocket server on this
    /// loopback address (default 127.0.0.1:8765); docs/recording.md.
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "127.0.0.1:8765")]
    pub view: Option<std::net::SocketAddr>,
    /// Overrides (default prefix: a fresh random one).
    #[command(flatten)]
    pub overrides: ZenohOverrideArgs,
}

/// `spacepose replay`.
#[derive(Debug, Args)]
pub struct ReplayArgs {
    /// The recording: an MCAP file written by `demo --record` or `up --record`.
    #[arg(value_name = "RUN.mcap")]
    pub input: PathBuf,
    /// Run this descriptor instead of the one recorded in the file.
    #[arg(long)]
    pub deploy: Option<PathBuf>,
    /// Frames per second (0 = recorded speed); default: the recorded run's rate.
    #[arg(long)]
    pub rate_hz: Option<f64>,
    /// Write the comparison as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Seconds to wait for missing poses once the last frame is out.
    #[arg(long, default_value_t = 5.0)]
    pub linger_s: f64,
    /// Record the replay into this MCAP file.
    #[arg(long, value_name = "OUT.mcap")]
    pub record: Option<PathBuf>,
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
    Tracking(spacepose_eval::tracking::EvalTrackingArgs),
    /// CNN pose estimation + NDT refinement (seed 004 Tables III-IV) on held-out frames.
    Cnn(spacepose_eval::cnn::EvalCnnArgs),
    /// Template-matching acquisition (seed 002 §4): success rate, time, f_CONV.
    Tm(Box<spacepose_eval::tm::EvalTmArgs>),
    /// Regenerate (or --check) the results tables of the README and docs/
    /// from the committed runs under docs/results/.
    Tables(spacepose_eval::tables::TablesArgs),
}
