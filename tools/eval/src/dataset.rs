//! `spacepose dataset`: the synthetic CNN training set of seed 004 §IV.B
//! (simulated Mid-40 frames under domain randomisation, preprocessed into
//! depth images with soft labels), written as `.npy` files and `meta.json`.

use anyhow::{Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use spacepose_cnn::{DEFAULT_MIN_POINTS, DEFAULT_ROLL_STEP_DEG, DatasetConfig, Generator};
use std::path::PathBuf;
use std::time::Instant;

use crate::common::load_target;

/// `spacepose dataset`.
#[derive(Debug, Args)]
pub struct DatasetArgs {
    /// Built-in target (`deos`, `envisat`) or a mesh file (STL, OBJ, PLY).
    #[arg(long, default_value = "deos")]
    pub target: String,
    /// Scale applied to a mesh file's coordinates (to metres).
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// Number of samples.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub count: u64,
    /// Seed of every draw (sample i uses its own stream from (seed, i)).
    #[arg(long)]
    pub seed: u64,
    /// Output directory (created if missing; meta.json is written last).
    #[arg(long)]
    pub out: PathBuf,
    /// Depth image size N (64 to 224).
    #[arg(long, default_value_t = spacepose_cnn::DEFAULT_IMAGE_SIZE)]
    pub image_size: usize,
    /// Roll step Δα of the attitude classes (deg).
    #[arg(long, default_value_t = DEFAULT_ROLL_STEP_DEG)]
    pub roll_step: f64,
    /// Frames with fewer points in the ROI are re-drawn.
    #[arg(long, default_value_t = DEFAULT_MIN_POINTS)]
    pub min_points: usize,
    /// Worker threads (default: all cores). The output does not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
}

/// Runs the command.
pub fn run(args: &DatasetArgs) -> Result<()> {
    let target = load_target(&args.target, args.scale)?;
    let config = DatasetConfig {
        seed: args.seed,
        count: args.count as usize,
        image_size: args.image_size,
        roll_step_deg: args.roll_step,
        min_points: args.min_points,
    };
    let generator = Generator::new(target, config).context("invalid dataset configuration")?;
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = args.threads {
        pool = pool.num_threads(t);
    }
    let pool = pool.build().context("cannot start the worker threads")?;
    let bar = ProgressBar::new(args.count);
    let style = ProgressStyle::with_template(
        "{msg} [{bar:40}] {pos}/{len} samples ({per_sec}, {elapsed} elapsed, eta {eta})",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .progress_chars("=> ");
    bar.set_style(style);
    bar.set_message("generating");
    let start = Instant::now();
    let stats = pool
        .install(|| generator.write(&args.out, &|k| bar.inc(k)))
        .with_context(|| format!("writing the dataset to {}", args.out.display()))?;
    bar.finish_and_clear();
    let secs = start.elapsed().as_secs_f64();
    let p = generator.preprocess_config();
    println!(
        "wrote {} samples to {} in {:.1} s ({:.1} samples/s, {} threads): N = {}, l = {} m, m = {} classes; \
         {} frames re-drawn (< {} ROI points), mean {:.0} ROI points, max |p - c| {:.2} m",
        args.count,
        args.out.display(),
        secs,
        args.count as f64 / secs,
        pool.current_num_threads(),
        p.image_size,
        p.roi_side_m,
        generator.classes().len(),
        stats.redraws,
        args.min_points,
        stats.mean_points_in_roi,
        stats.max_abs_pos_offset_m,
    );
    Ok(())
}
