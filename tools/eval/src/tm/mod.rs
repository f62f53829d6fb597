//! `spacepose eval tm`: seed 002 on-line template matching with ICP
//! refinement on simulated frames, scored against truth (§4.2-4.5,
//! Fig. 8, Tables 2 and 4).
//!
//! Conditions: the raster sensor of seed 002 §4.1 (40°×40° at 1°,
//! `SensorConfig::raster_seed002`), or with `--sensor mid40` the suite's
//! Livox Mid-40 and the init service's 2 cm voxel filter, with every effect on but facility
//! clutter (noise, line-of-sight error, outliers, detection losses, beam
//! divergence, reflections, motion blur). A solution is a success when the
//! attitude error after ICP is below 3° (§4.2), with d_sym (seed 004
//! Eq. 14) for targets with symmetries. `--sensor-effects seed002` keeps
//! only the effects seed 002 §3.2 simulates (detection, range and
//! line-of-sight noise, 4σ range outliers), to tell what the extra effects
//! cost. Acquisitions run one after the
//! other, so the time is that of one acquisition with the requested
//! threads; frames are simulated beforehand, in parallel.

mod args;
mod render;
mod report;
mod scoring;

pub use args::{EvalTmArgs, SensorEffects, TmOptions, TmSensor};
pub use report::{TemplateCounts, TmFrame, TmReport};
pub use scoring::SUCCESS_DEG;

use crate::common::load_target;
use crate::common::progress_bar;
use anyhow::{Context, Result, bail};
use rayon::prelude::*;
use scoring::{score, summarise};
use spacepose_acquisition::TemplateMatcher;
use spacepose_geometry::voxel_filter;
use spacepose_lidar_sim::{Frame, LidarSimulator};
use spacepose_scenario::ScenarioKind;
use spacepose_scenario::{ScenarioConfig, build};

/// Runs the acquisitions of `scenario` and scores them.
pub fn evaluate(scenario_arg: ScenarioKind, options: &TmOptions) -> Result<TmReport> {
    if !matches!(scenario_arg, ScenarioKind::Random | ScenarioKind::Ellipse) {
        bail!("template matching is evaluated on random or ellipse (seed 002 §4.3)");
    }
    let target = load_target(&options.target, options.scale)?;
    let sensor = options.sensor.config();
    let matching = options.matching()?;
    let matcher = TemplateMatcher::new(target.clone(), sensor.clone(), matching.clone())
        .context("building the template matcher")?;
    let mut scenario_config = ScenarioConfig::default_for(scenario_arg);
    scenario_config.seed = options.seed;
    scenario_config.range_m = options.range;
    let count = options
        .count
        .map(|c| c as usize)
        .unwrap_or(match scenario_arg {
            ScenarioKind::Random => 50,
            _ => usize::MAX,
        });
    scenario_config.random_frames = count.min(100_000);
    let scenario = build(&scenario_config).context("invalid scenario")?;
    let count = count.min(scenario.natural_frame_count());
    let mut sim_sensor = sensor;
    sim_sensor.effects = options.sensor_effects.effects();
    let simulator = LidarSimulator::new(target.clone(), sim_sensor).context("simulator")?;
    let end_times = scenario.frame_end_times(count);
    let bar = progress_bar(count as u64, "acquiring");
    let mut frames = Vec::with_capacity(count);
    for (b, batch) in end_times.chunks(16).enumerate() {
        let simulated: Vec<Frame> = batch
            .par_iter()
            .enumerate()
            .map(|(i, &t)| {
                let mut rng = LidarSimulator::frame_rng(options.seed, (b * 16 + i) as u64);
                simulator.simulate(&scenario.state_at(t), &mut rng)
            })
            .collect();
        for (i, frame) in simulated.iter().enumerate() {
            let points = match options.sensor.voxel_leaf_m() {
                Some(leaf) => voxel_filter(&frame.points, leaf)
                    .map(|v| v.points)
                    .context("voxel filter")?,
                None => frame.points.clone(),
            };
            let result = matcher.acquire(&points);
            frames.push(score(b * 16 + i, frame, result, target.symmetries()));
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    Ok(summarise(
        target.name(),
        scenario.name(),
        options,
        matching,
        matcher.grid_len(),
        frames,
    ))
}

/// The report as text: the header line, the summary table and, with
/// `with_frames`, the per-frame table.
pub fn render(report: &TmReport, with_frames: bool) -> String {
    let mut out = render::header(report);
    out.push_str(&render::summary_table(report).render());
    if with_frames {
        out.push('\n');
        out.push_str(&render::frames_table(&report.frames).render());
    }
    out
}

/// `spacepose eval tm`.
pub fn run(args: &EvalTmArgs) -> Result<()> {
    let report = evaluate(args.scenario, &args.options)?;
    println!("{}", render(&report, args.frames));
    if let Some(path) = &args.json {
        let json = serde_json::to_string_pretty(&report)?;
        std::fs::write(path, json).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}
