//! Stand-alone dataset generator, identical output to `spacepose dataset`
//! (same [`Generator`], same seeds), for when the `spacepose` binary cannot be
//! built. Progress goes to stderr as lines.
//!
//! `cargo run --release -p spacepose-cnn --example gen_dataset -- --count 256 --seed 90 --out DIR [--image-size 64] [--threads 2] [--target deos]`

use spacepose_cnn::{DEFAULT_MIN_POINTS, DEFAULT_ROLL_STEP_DEG, DatasetConfig, Generator};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let get = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let count: usize = get("--count").ok_or("--count is required")?.parse()?;
    let seed: u64 = get("--seed").ok_or("--seed is required")?.parse()?;
    let out = std::path::PathBuf::from(get("--out").ok_or("--out is required")?);
    let image_size: usize = get("--image-size").unwrap_or_else(|| "64".into()).parse()?;
    let target = get("--target").unwrap_or_else(|| "deos".into());
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = get("--threads") {
        pool = pool.num_threads(t.parse()?);
    }
    let pool = pool.build()?;
    let generator = Generator::new(
        Arc::new(spacepose_model::Target::resolve(&target, 1.0)?),
        DatasetConfig {
            seed,
            count,
            image_size,
            roll_step_deg: DEFAULT_ROLL_STEP_DEG,
            min_points: DEFAULT_MIN_POINTS,
        },
    )?;
    let done = AtomicU64::new(0);
    let start = Instant::now();
    let progress = |k: u64| {
        let d = done.fetch_add(k, Ordering::Relaxed) + k;
        if d.is_multiple_of(500) || d as usize == count {
            let s = start.elapsed().as_secs_f64();
            eprintln!(
                "{d}/{count} samples, {s:.0} s, {:.1} samples/s",
                d as f64 / s
            );
        }
    };
    let stats = pool.install(|| generator.write(&out, &progress))?;
    let secs = start.elapsed().as_secs_f64();
    println!(
        "wrote {count} samples to {} in {secs:.1} s ({:.1} samples/s, {} threads); m = {}, {} re-drawn, mean {:.0} ROI points, max |p - c| {:.2} m",
        out.display(),
        count as f64 / secs,
        pool.current_num_threads(),
        generator.classes().len(),
        stats.redraws,
        stats.mean_points_in_roi,
        stats.max_abs_pos_offset_m
    );
    Ok(())
}
