//! `spacepose eval cnn`: seed 004's CNN pose estimation with NDT refinement
//! on a held-out synthetic set, scored against truth as Table III (success
//! before and after refinement: < 5° with d_sym, Eq. 14, and < 15 cm; mean
//! errors over the successes) and timed as Table IV (preprocessing,
//! inference, refinement; one thread).
//!
//! Frames come from the training set's generator (`spacepose_cnn::Generator`:
//! domain-randomised Mid-40 frames at 2.5-20 m with motion blur) with a seed
//! never used for training (training 1, validation 2, smoke 90). They are
//! simulated in parallel, chunk by chunk; the estimates then run one after
//! the other on the calling thread, so the timings are those of one core.
mod args;
mod render;
mod report;
mod scoring;
mod summary;

pub use args::{EngineArg, EvalCnnArgs};
pub use report::{
    CnnFrame, CnnReport, FconvStats, MeanStd, RangeBin, RawRefined, TimeSplit, TimeStats,
};
pub use scoring::{SUCCESS_CM, SUCCESS_DEG};

use crate::common::load_target;
use crate::common::progress_bar;
use anyhow::{Context, Result, bail};
use args::engine;
use rayon::prelude::*;
use spacepose_cnn::{
    CnnEstimator, DEFAULT_MIN_POINTS, DatasetConfig, EstimatorConfig, GeneratedFrame, Generator,
};
use std::path::PathBuf;

/// Seeds used for training, validation and the smoke set: refused.
pub const TRAINING_SEEDS: [u64; 3] = [1, 2, 90];
/// Frames simulated in parallel before they are estimated in turn.
const CHUNK: usize = 64;

/// Range noise of the frames outside the training, over the Mid-40's.
const MISMATCH_NOISE_FACTOR: f64 = 1.5;
/// Largest angular rate of the frames outside the training (deg/s).
const MISMATCH_MAX_RATE_DEG_S: f64 = 10.0;

/// `generator` making frames of `target` as built (seeded by `seed`), with
/// [`MISMATCH_NOISE_FACTOR`] times the range noise and rates up to
/// [`MISMATCH_MAX_RATE_DEG_S`].
fn outside_training(
    generator: Generator,
    target: &spacepose_model::Target,
    seed: u64,
) -> Result<Generator> {
    let world = spacepose_model::AsBuilt::default()
        .apply(target, seed)
        .context("building the target as built")?;
    let mut sensor = spacepose_lidar_sim::SensorConfig::livox_mid40();
    sensor.range_sigma_m *= MISMATCH_NOISE_FACTOR;
    Ok(generator.outside_training(std::sync::Arc::new(world), sensor, MISMATCH_MAX_RATE_DEG_S)?)
}

/// Generates the held-out set and scores every estimate.
pub fn evaluate(args: &EvalCnnArgs) -> Result<CnnReport> {
    if TRAINING_SEEDS.contains(&args.seed) {
        bail!(
            "seed {} was used for training, validation or smoke tests ({TRAINING_SEEDS:?}): pick another",
            args.seed
        );
    }
    let target = load_target(&args.target, 1.0)?;
    let model = args
        .model
        .clone()
        .unwrap_or_else(|| PathBuf::from("services/core/cnn/models").join(target.name()));
    let mut config = EstimatorConfig::default();
    if let Some(f_max) = args.f_max {
        config.refinement.f_max_m2 = f_max;
    }
    if let Some(h) = args.hypotheses {
        config.hypotheses = h;
    }
    if let Some(max_points) = args.max_points {
        config.refinement.max_points = max_points;
    }
    if let Some(stages) = &args.ndt_stages {
        config.refinement.ndt_stages_m = if stages == "none" {
            Vec::new()
        } else {
            stages
                .split(',')
                .map(|s| s.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .with_context(|| format!("--ndt-stages {stages:?}"))?
        };
    }
    let estimator = CnnEstimator::load_with(&model, engine(args)?, target.clone(), config.clone())
        .with_context(|| format!("loading the CNN from {}", model.display()))?;
    let generator = Generator::new(
        target.clone(),
        DatasetConfig {
            seed: args.seed,
            count: args.count as usize,
            image_size: estimator.preprocess_config().image_size,
            roll_step_deg: config.roll_step_deg,
            min_points: DEFAULT_MIN_POINTS,
        },
    )?;
    let generator = match args.mismatch {
        false => generator,
        true => outside_training(generator, &target, args.seed)?,
    };
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = args.sim_threads {
        pool = pool.num_threads(t);
    }
    let pool = pool
        .build()
        .context("cannot start the simulation threads")?;
    let bar = progress_bar(args.count, "cnn");
    let mut frames = Vec::with_capacity(args.count as usize);
    for start in (0..args.count).step_by(CHUNK) {
        let end = (start + CHUNK as u64).min(args.count);
        let chunk: Vec<GeneratedFrame> = pool.install(|| {
            (start..end)
                .into_par_iter()
                .map(|i| generator.frame(i))
                .collect::<Result<_, _>>()
        })?;
        for (i, f) in (start..end).zip(&chunk) {
            frames.push(scoring::score(&estimator, i, f));
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    Ok(summary::report(args, &estimator, &model, config, frames))
}

/// Prints Tables III and IV.
pub fn print(report: &CnnReport, frames: bool) {
    println!("{}", render::summary_line(report));
    println!(
        "\nTable III (success: < {SUCCESS_DEG}° with d_sym and < {SUCCESS_CM} cm; errors over the successes)"
    );
    print!("{}", render::table3(report).render());
    println!("\nTable IV (one thread)");
    print!("{}", render::table4(&report.time_ms).render());
    println!("\n{}", render::fconv_line(&report.fconv));
    println!("{}", render::acceptance_line(report));
    print!("\n{}", render::range_table(&report.by_range).render());
    if frames {
        print!("\n{}", render::frames_table(&report.frames).render());
    }
}

/// Runs the command.
pub fn run(args: &EvalCnnArgs) -> Result<()> {
    let report = evaluate(args)?;
    print(&report, args.frames);
    if let Some(path) = &args.json {
        std::fs::write(path, serde_json::to_string_pretty(&report)?)
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
