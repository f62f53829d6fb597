//! The error type of the CNN data crate.

use std::path::PathBuf;

/// Everything that can go wrong in `spacepose-cnn`.
///
/// Bad input (an empty or non-finite cloud, a label vector of the wrong
/// length, a corrupt `.npy` file) is reported here, never as a panic.
#[derive(Debug, thiserror::Error)]
pub enum CnnError {
    /// The image size N is outside the supported range.
    #[error("image size must be in {min}..={max} pixels, got {got}")]
    ImageSize {
        /// The requested size.
        got: usize,
        /// Smallest supported size.
        min: usize,
        /// Largest supported size.
        max: usize,
    },

    /// A configuration value is NaN, infinite, zero or negative where it must not be.
    #[error("invalid parameter {name}: {value}")]
    InvalidParameter {
        /// Name of the parameter.
        name: &'static str,
        /// Its value.
        value: f64,
    },

    /// The cloud to preprocess has no point.
    #[error("empty point cloud")]
    EmptyCloud,

    /// The trimmed centroid failed (non-finite coordinates, bad trim).
    #[error("centroid: {0}")]
    Centroid(#[from] spacepose_geometry::GeometryError),

    /// A label vector does not match the class table.
    #[error("label vector has {got} entries, the class table has {expected}")]
    LabelLength {
        /// Entries received.
        got: usize,
        /// Number of classes.
        expected: usize,
    },

    /// A label vector holds NaN, infinity or a negative value, or sums to zero.
    #[error("label vector is not a probability vector ({0})")]
    BadLabels(&'static str),

    /// The symmetry group of the target cannot be used (not rotations, no identity first).
    #[error("unsupported symmetry group: {0}")]
    Symmetry(String),

    /// The target could not be loaded or simulated.
    #[error("simulator: {0}")]
    Simulator(#[from] spacepose_lidar_sim::SimError),

    /// A sample could not be drawn with enough points after many attempts.
    #[error(
        "sample {index}: no frame with >= {min_points} points in the ROI after {attempts} draws"
    )]
    TooManyRedraws {
        /// Sample index.
        index: u64,
        /// Minimum number of ROI points required.
        min_points: usize,
        /// Draws attempted.
        attempts: u32,
    },

    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },

    /// A `.npy` file is malformed or not what was expected.
    #[error("{path}: bad .npy file: {reason}")]
    Npy {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },

    /// Serialising the dataset metadata failed.
    #[error("meta.json: {0}")]
    Json(#[from] serde_json::Error),

    /// A model directory is missing or lacks `model.onnx` / `model.json`.
    #[error("model directory {}: {reason}", path.display())]
    ModelDir {
        /// The directory.
        path: PathBuf,
        /// What is missing.
        reason: String,
    },

    /// `model.json` cannot be parsed.
    #[error("{}: bad model metadata: {reason}", path.display())]
    ModelMeta {
        /// The file.
        path: PathBuf,
        /// The parser's message.
        reason: String,
    },

    /// The model was trained for another preprocessing or class table.
    #[error(
        "{}: the model was trained with {field} = {model}, this build expects {expected} \
         (retrain the model or use the matching configuration)",
        path.display()
    )]
    ModelMismatch {
        /// The model directory.
        path: PathBuf,
        /// The field that differs.
        field: &'static str,
        /// The model's value.
        model: String,
        /// The value in use here.
        expected: String,
    },

    /// Loading or running the network failed.
    #[error("network: {0}")]
    Inference(#[from] spacepose_inference::InferenceError),

    /// Building or loading the NDT map or the ICP model failed.
    #[error("refinement model: {0}")]
    Registration(#[from] spacepose_registration::RegistrationError),

    /// The target named by the model cannot be resolved.
    #[error("target {name:?}: {reason}")]
    Target {
        /// The target name.
        name: String,
        /// Why it cannot be used.
        reason: String,
    },

    /// The cloud has too few finite points to estimate a pose.
    #[error("{valid} finite points of {total}, at least {required} needed")]
    TooFewPoints {
        /// Finite points.
        valid: usize,
        /// Points given.
        total: usize,
        /// Minimum required.
        required: usize,
    },
}

/// Shorthand for an I/O error on `path`.
pub(crate) fn io_err(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> CnnError + '_ {
    move |source| CnnError::Io {
        path: path.to_path_buf(),
        source,
    }
}
