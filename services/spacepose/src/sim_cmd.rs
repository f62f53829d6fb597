//! `spacepose sim`: simulated lidar frames with ground truth on disk.

use crate::cli::{FormatArg, PatternArg, SimArgs};
use crate::common::load_target;
use crate::truth_csv;
use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use spacepose_geometry::{CloudFormat, write_cloud};
use spacepose_lidar_sim::{Effects, LidarSimulator, SensorConfig};
use spacepose_scenario::{ScenarioConfig, build};
use std::fs;
use std::io::Write;
use std::path::Path;

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
    let mut scenario_config = ScenarioConfig::default_for(args.scenario.kind());
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

/// A progress bar on stderr (hidden when stderr is not a terminal).
pub fn progress_bar(len: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    let style = ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} frames ({eta})")
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
    bar.set_style(style);
    bar.set_message(what.to_string());
    bar
}
