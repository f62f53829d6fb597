//! Errors of the inference crate.

use std::path::PathBuf;

use thiserror::Error;

/// Everything that can go wrong while loading or running a pose network.
///
/// Load-time variants name the model file and say what the model contract
/// (input `depth` [1, 1, N, N]; outputs `probs` [1, m] and `pos` [1, 3])
/// expected versus what the file holds.
#[derive(Debug, Error)]
pub enum InferenceError {
    /// The expected model shape itself is unusable (zero image size or classes).
    #[error(
        "invalid expected model shape: image_size {image_size}, classes {classes} (both must be > 0)"
    )]
    InvalidExpectedShape {
        /// Requested image side N.
        image_size: usize,
        /// Requested number of attitude classes m.
        classes: usize,
    },
    /// The model file does not exist or is not a regular file.
    #[error("model file {} not found (or not a regular file)", path.display())]
    ModelNotFound {
        /// The path that was given.
        path: PathBuf,
    },
    /// The engine could not parse or analyse the file as an ONNX model.
    #[error("model file {} could not be loaded by {engine}: {reason}", path.display())]
    ModelInvalid {
        /// The model file.
        path: PathBuf,
        /// Engine name (`tract` or `ort`).
        engine: &'static str,
        /// The engine's message.
        reason: String,
    },
    /// The model takes a depth image of another size than the expected N × N.
    #[error(
        "model file {} takes depth images of shape {found}, expected [1, 1, {expected}, {expected}] (image_size {expected}): \
         the model was trained for another image size",
        path.display()
    )]
    ImageSizeMismatch {
        /// The model file.
        path: PathBuf,
        /// Expected image side N.
        expected: usize,
        /// The input shape the model declares.
        found: String,
    },
    /// The model outputs another number of class probabilities than expected.
    #[error(
        "model file {} outputs {found} class probabilities, expected {expected}: the model was trained for another class table",
        path.display()
    )]
    ClassCountMismatch {
        /// The model file.
        path: PathBuf,
        /// Expected number of classes m.
        expected: usize,
        /// Number of classes the model outputs.
        found: usize,
    },
    /// The model's input does not follow the contract (count, name, type, rank).
    #[error("model file {} input: expected {expected}, found {found}", path.display())]
    InputMismatch {
        /// The model file.
        path: PathBuf,
        /// What the contract expects.
        expected: String,
        /// What the model declares.
        found: String,
    },
    /// The model's outputs do not follow the contract (names, shapes, softmax).
    #[error("model file {} outputs: expected {expected}, found {found}", path.display())]
    OutputMismatch {
        /// The model file.
        path: PathBuf,
        /// What the contract expects.
        expected: String,
        /// What the model produces.
        found: String,
    },
    /// The depth image given to `infer` has the wrong number of pixels.
    #[error(
        "depth image has {found} values, expected {expected} (N × N row-major, N = {image_size})"
    )]
    InputLength {
        /// N × N.
        expected: usize,
        /// Length of the given slice.
        found: usize,
        /// N.
        image_size: usize,
    },
    /// The depth image holds a NaN or infinite value.
    #[error("depth image value {index} is not finite ({value})")]
    NonFiniteInput {
        /// Row-major index of the first bad value.
        index: usize,
        /// The value.
        value: f32,
    },
    /// The network produced a NaN or infinite value.
    #[error("model file {} produced a non-finite value in output `{output}`", path.display())]
    NonFiniteOutput {
        /// The model file.
        path: PathBuf,
        /// Output name.
        output: &'static str,
    },
    /// The engine failed while running the network.
    #[error("{engine} failed to run model file {}: {reason}", path.display())]
    Run {
        /// The model file.
        path: PathBuf,
        /// Engine name.
        engine: &'static str,
        /// The engine's message.
        reason: String,
    },
    /// The ONNX Runtime engine was requested but this build does not include it.
    #[error(
        "the ONNX Runtime (ort) engine is not compiled into this build: rebuild with `--features ort` \
         (e.g. `cargo build --release -p spacepose-inference --features ort`) or use the tract engine"
    )]
    OrtNotCompiled,
    /// No ONNX Runtime shared library at the given path.
    #[error(
        "ONNX Runtime library {} not found: install the onnxruntime wheel (pip install onnxruntime==1.31.1) \
         and point ORT_DYLIB_PATH at .../site-packages/onnxruntime/capi/libonnxruntime.so.<version>",
        path.display()
    )]
    OrtLibraryNotFound {
        /// The library path that was given.
        path: PathBuf,
    },
    /// No ONNX Runtime shared library in any of the default places.
    #[error(
        "no ONNX Runtime library found (searched: {searched}): install the onnxruntime wheel \
         (pip install onnxruntime==1.31.1) and set ORT_DYLIB_PATH to its capi/libonnxruntime.so.<version>"
    )]
    OrtLibraryNotFoundAnywhere {
        /// The places searched, comma-separated.
        searched: String,
    },
    /// The ONNX Runtime library exists but could not be loaded or initialised.
    #[error("ONNX Runtime library {} could not be loaded: {reason}", path.display())]
    OrtLibraryLoad {
        /// The library path.
        path: PathBuf,
        /// The loader's message.
        reason: String,
    },
    /// ONNX Runtime is loaded once per process: another library was loaded first.
    #[error(
        "ONNX Runtime library {} was requested but {} is already loaded in this process (one library per process)",
        requested.display(),
        loaded.display()
    )]
    OrtLibraryConflict {
        /// The library loaded first.
        loaded: PathBuf,
        /// The library asked for now.
        requested: PathBuf,
    },
}
