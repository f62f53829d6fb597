//! `spacepose sim`: simulated lidar frames with ground truth on disk.

use crate::common::{load_target, progress_bar};
use crate::truth_csv;
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use rayon::prelude::*;
use spacepose_geometry::{CloudFormat, write_cloud};
use spacepose_lidar_sim::{Effects, LidarSimulator, SensorConfig};
use spacepose_scenario::ScenarioKind;
use spacepose_scenario::{ScenarioConfig, build};
use std::fs;
use std::io::Write;
use std::path::Path;
use std::path::PathBuf;

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
    #[arg(long, default_value = "tumbling")]
    pub scenario: ScenarioKind,
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

/// The sensor configuration the arguments describe.
pub fn sensor_config(
    pattern: PatternArg,
    integration_time: Option<f64>,
    clutter: bool,
    ideal: bool,
) -> Result<SensorConfig> {
    let mut config = match pattern {
        PatternArg::Rosette => SensorConfig::livox_mid40(),
        PatternArg::Raster => SensorConfig::raster_seed002(),
    };
    if let Some(t) = integration_time {
        config.integration_time_s = t;
    }
    if ideal {
        config.effects = Effects::none();
    }
    config.effects.clutter = clutter;
    config.validate().context("invalid sensor configuration")?;
    Ok(config)
}

/// Runs the command.
pub fn run(args: &SimArgs) -> Result<()> {
    let target = load_target(&args.target, args.scale)?;
    let mut scenario_config = ScenarioConfig::default_for(args.scenario);
    scenario_config.seed = args.seed;
    scenario_config.compression = args.compression;
    scenario_config.range_m = args.range;
    scenario_config.random_frames = scenario_config.random_frames.max(args.frames as usize);
    let scenario = build(&scenario_config).context("invalid scenario")?;
    let config = sensor_config(
        args.pattern,
        args.integration_time,
        args.clutter,
        args.ideal,
    )?;
    let simulator = LidarSimulator::new(target, config).context("cannot build the simulator")?;
    fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let format = match args.format {
        FormatArg::Pcd => CloudFormat::PcdBinary,
        FormatArg::PcdAscii => CloudFormat::PcdAscii,
        FormatArg::Ply => CloudFormat::PlyBinary,
    };
    let frames = args.frames as usize;
    let end_times = scenario.frame_end_times(frames);
    let bar = progress_bar(frames as u64, "simulating");
    let rows: Vec<Result<String>> = end_times
        .par_iter()
        .enumerate()
        .map(|(k, &t_end)| {
            let truth = scenario.state_at(t_end);
            let mut rng = LidarSimulator::frame_rng(args.seed, k as u64);
            let frame = simulator
                .try_simulate(&truth, &mut rng)
                .with_context(|| format!("frame {k}"))?;
            let path = args
                .out
                .join(format!("frame_{k:06}.{}", format.extension()));
            write_cloud(&path, &frame.points, format)
                .with_context(|| format!("writing {}", path.display()))?;
            bar.inc(1);
            Ok(truth_csv::row(
                k,
                frame.scan_start,
                frame.scan_end,
                frame.points.len(),
                &frame.truth,
            ))
        })
        .collect();
    bar.finish_and_clear();
    write_truth(&args.out.join("truth.csv"), rows)?;
    println!(
        "wrote {frames} frames and truth.csv to {}",
        args.out.display()
    );
    Ok(())
}

fn write_truth(path: &Path, rows: Vec<Result<String>>) -> Result<()> {
    let mut text = String::from(truth_csv::HEADER);
    text.push('\n');
    for row in rows {
        text.push_str(&row?);
        text.push('\n');
    }
    let mut file =
        fs::File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
    file.write_all(text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    if text.lines().count() < 2 {
        bail!("no frame written");
    }
    Ok(())
}
