//! `spacepose train --target DIR`: one command from a target package to a
//! CNN in it (issue 24). It
//! 1. generates the training and validation sets of seed 004 §IV.B for the
//!    package's target (`spacepose dataset`, in process, progress bar);
//! 2. runs `tools/train/train.py` (PyTorch on the CPU, its own progress
//!    bars) with the package's `cnn/` directory as the output, where it
//!    exports `model.onnx`, `model.json` and `training-log.txt`;
//! 3. loads the result with the suite's own loader, checked against the
//!    package's target and class table, so a model that init would refuse
//!    is reported here.
//!
//! The init service then uses the model with no configuration (see its
//! README). Training needs the venv of `tools/train/setup.sh`; it never
//! runs in CI.

use crate::dataset::{self, DatasetArgs};
use anyhow::{Context, Result, bail, ensure};
use clap::Args;
use spacepose_cnn::{CnnEstimator, EstimatorConfig};
use spacepose_inference::Engine;
use spacepose_model::package::{CNN_DIR, is_package_dir, load_package};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;
use std::time::Instant;

/// `spacepose train`.
#[derive(Debug, Args)]
pub struct TrainArgs {
    /// Target package directory (`spacepose target prepare`); the model is
    /// written to its `cnn/` subdirectory.
    #[arg(long)]
    pub target: PathBuf,
    /// Training samples (the committed deos model: 60,000).
    #[arg(long, default_value_t = 60_000)]
    pub count: u64,
    /// Validation samples.
    #[arg(long, default_value_t = 4_000)]
    pub val_count: u64,
    /// Seed of the training set; the validation set uses seed + 1.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Training epochs.
    #[arg(long, default_value_t = 36)]
    pub epochs: u32,
    /// Stop training after this many minutes (then export what it has).
    #[arg(long)]
    pub max_minutes: Option<f64>,
    /// PyTorch threads.
    #[arg(long, default_value_t = 1)]
    pub threads: usize,
    /// Where the datasets are written (default: `DIR/cnn/data`); they are
    /// removed after a successful run unless `--keep-data`.
    #[arg(long)]
    pub work: Option<PathBuf>,
    /// Keep the datasets.
    #[arg(long)]
    pub keep_data: bool,
    /// The training script (default: `tools/train/train.py` in the current
    /// directory or one of its parents, i.e. a spacepose checkout).
    #[arg(long)]
    pub trainer: Option<PathBuf>,
    /// The Python with torch (default: the trainer's `.venv/bin/python`,
    /// made by `tools/train/setup.sh`).
    #[arg(long)]
    pub python: Option<PathBuf>,
}

/// Runs the command.
pub fn run(args: &TrainArgs) -> Result<()> {
    ensure!(
        is_package_dir(&args.target),
        "{} is not a target package directory (make one with `spacepose target prepare MESH --out DIR`)",
        args.target.display()
    );
    let package = load_package(&args.target)
        .with_context(|| format!("loading the package {}", args.target.display()))?;
    let trainer = trainer_script(args.trainer.as_deref())?;
    let python = python_for(&trainer, args.python.as_deref())?;
    let out = args.target.join(CNN_DIR);
    let work = args.work.clone().unwrap_or_else(|| out.join("data"));
    let spec = args.target.display().to_string();
    let start = Instant::now();
    for (set, count, seed) in [
        ("train", args.count, args.seed),
        ("val", args.val_count, args.seed + 1),
    ] {
        println!("dataset {set}: {count} samples, seed {seed}");
        dataset::run(&DatasetArgs {
            target: spec.clone(),
            scale: 1.0,
            count,
            seed,
            out: work.join(set),
            image_size: spacepose_cnn::DEFAULT_IMAGE_SIZE,
            roll_step: spacepose_cnn::DEFAULT_ROLL_STEP_DEG,
            min_points: spacepose_cnn::DEFAULT_MIN_POINTS,
            threads: None,
        })?;
    }
    let data_s = start.elapsed().as_secs_f64();
    let train_start = Instant::now();
    train(args, &python, &trainer, &work, &out)?;
    let train_s = train_start.elapsed().as_secs_f64();
    let target = Arc::new(package.target);
    CnnEstimator::load_with(&out, Engine::Tract, target, EstimatorConfig::default())
        .with_context(|| format!("the trained model in {} does not load", out.display()))?;
    if !args.keep_data && args.work.is_none() {
        std::fs::remove_dir_all(&work)
            .with_context(|| format!("removing the datasets in {}", work.display()))?;
    }
    println!(
        "model for {} in {} (datasets {:.1} min, training {:.1} min); init uses it when the \
         target is this package; `spacepose eval cnn --target {} --model {}` measures it",
        spec,
        out.display(),
        data_s / 60.0,
        train_s / 60.0,
        spec,
        out.display()
    );
    Ok(())
}

/// Runs the training script, its output shown as it comes.
fn train(args: &TrainArgs, python: &Path, trainer: &Path, work: &Path, out: &Path) -> Result<()> {
    let mut command = Command::new(python);
    command
        .arg(trainer)
        .arg("--data")
        .arg(work.join("train"))
        .arg("--val")
        .arg(work.join("val"))
        .arg("--out")
        .arg(out)
        .arg("--epochs")
        .arg(args.epochs.to_string())
        .arg("--threads")
        .arg(args.threads.to_string());
    if let Some(m) = args.max_minutes {
        command.arg("--max-minutes").arg(m.to_string());
    }
    let status = command
        .status()
        .with_context(|| format!("running {} {}", python.display(), trainer.display()))?;
    if !status.success() {
        bail!(
            "training failed ({status}); its log is in {}",
            out.display()
        );
    }
    Ok(())
}

/// The training script: `given`, else `tools/train/train.py` under the
/// current directory or its nearest parent that has it.
fn trainer_script(given: Option<&Path>) -> Result<PathBuf> {
    if let Some(path) = given {
        ensure!(path.is_file(), "no training script at {}", path.display());
        return Ok(path.to_path_buf());
    }
    let cwd = std::env::current_dir().context("the current directory")?;
    cwd.ancestors()
        .map(|d| d.join("tools/train/train.py"))
        .find(|p| p.is_file())
        .with_context(|| {
            format!(
                "no tools/train/train.py in {} or its parents: run from a spacepose checkout or \
                 give --trainer",
                cwd.display()
            )
        })
}

/// The Python that runs `trainer`: `given`, else the venv beside it.
fn python_for(trainer: &Path, given: Option<&Path>) -> Result<PathBuf> {
    let python = match given {
        Some(p) => p.to_path_buf(),
        None => trainer.with_file_name(".venv").join("bin").join("python"),
    };
    ensure!(
        python.exists(),
        "no Python at {}: create the training venv with tools/train/setup.sh (once, ~2 min, \
         4.5 GB from PyPI) or give --python",
        python.display()
    );
    Ok(python)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_directory_that_is_not_a_package_is_refused_before_any_work() {
        let tmp = tempfile::tempdir().unwrap();
        let args = TrainArgs {
            target: tmp.path().to_path_buf(),
            count: 1,
            val_count: 1,
            seed: 1,
            epochs: 1,
            max_minutes: None,
            threads: 1,
            work: None,
            keep_data: false,
            trainer: None,
            python: None,
        };
        let e = run(&args).unwrap_err().to_string();
        assert!(e.contains("not a target package"), "{e}");
        assert!(!tmp.path().join(CNN_DIR).exists());
    }

    #[test]
    fn a_missing_venv_names_the_setup_script() {
        let tmp = tempfile::tempdir().unwrap();
        let trainer = tmp.path().join("train.py");
        std::fs::write(&trainer, "").unwrap();
        let e = python_for(&trainer, None).unwrap_err().to_string();
        assert!(e.contains("tools/train/setup.sh"), "{e}");
        assert!(trainer_script(Some(&tmp.path().join("no.py"))).is_err());
        assert_eq!(trainer_script(Some(&trainer)).unwrap(), trainer);
    }
}
