//! The arguments of `eval cnn` and the inference engine they choose.

use anyhow::Result;
use clap::{Args, ValueEnum};
use spacepose_inference::{Engine, find_ort_library};
use std::path::PathBuf;

/// Inference engines.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum EngineArg {
    /// tract-onnx (pure Rust).
    Tract,
    /// ONNX Runtime (build with `--features ort`).
    Ort,
}

/// `spacepose eval cnn`.
#[derive(Debug, Args)]
pub struct EvalCnnArgs {
    /// Built-in target or mesh file (the model must be trained for it).
    #[arg(long, default_value = "deos")]
    pub target: String,
    /// Model directory (model.onnx + model.json); default services/core/cnn/models/<target>.
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Held-out frames.
    #[arg(long, default_value_t = 1000, value_parser = clap::value_parser!(u64).range(1..))]
    pub count: u64,
    /// Seed of the held-out set (never 1, 2 or 90: training, validation, smoke).
    #[arg(long, default_value_t = 1001)]
    pub seed: u64,
    /// Inference engine.
    #[arg(long, value_enum, default_value = "tract")]
    pub engine: EngineArg,
    /// ONNX Runtime library (default: $ORT_DYLIB_PATH or tools/train/.venv's wheel).
    #[arg(long)]
    pub ort_library: Option<PathBuf>,
    /// f_MAX (m²) of the acceptance check (default: the estimator's).
    #[arg(long)]
    pub f_max: Option<f64>,
    /// Wider NDT stages before the final 7.5 cm one (m, comma-separated;
    /// "none" for the paper's single stage). Default: the estimator's.
    #[arg(long)]
    pub ndt_stages: Option<String>,
    /// Attitude hypotheses refined at most (1 = the paper). Default: the estimator's.
    #[arg(long)]
    pub hypotheses: Option<usize>,
    /// Points kept for the refinement (0 = all). Default: the estimator's.
    #[arg(long)]
    pub max_points: Option<usize>,
    /// Threads simulating the frames (default: all cores); estimates use one.
    #[arg(long)]
    pub sim_threads: Option<usize>,
    /// Write the report as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Frames outside what the network was trained on (issue 25 item 3):
    /// of the target as built (`spacepose_model::AsBuilt`'s defaults,
    /// drawn from the seed), with 1.5 times the Mid-40's range noise and
    /// angular rates up to 10°/s (training: 5°/s); the estimator keeps the
    /// nominal target.
    #[arg(long)]
    pub mismatch: bool,
    /// Also list every frame.
    #[arg(long)]
    pub frames: bool,
}

/// The inference engine `args` ask for (ONNX Runtime: the given library,
/// or the one found).
pub fn engine(args: &EvalCnnArgs) -> Result<Engine> {
    Ok(match args.engine {
        EngineArg::Tract => Engine::Tract,
        EngineArg::Ort => Engine::Ort {
            library: match &args.ort_library {
                Some(p) => p.clone(),
                None => find_ort_library()?,
            },
        },
    })
}
