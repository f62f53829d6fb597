//! ONNX inference of the seed 004 pose network (§III.D): a depth image of
//! N × N pixels in, a softmax over m attitude classes and a 3-vector position
//! offset out. The model contract (notes/acq-design.md): input `depth`
//! float32 [1, 1, N, N]; outputs `probs` float32 [1, m] and `pos` float32
//! [1, 3] in metres (tanh × l/2, target origin minus ROI centre).
//!
//! Engines: tract-onnx (default, pure Rust) and ONNX Runtime through `ort`
//! (crate feature `ort`, library loaded at run time: nothing is downloaded
//! at build time). Both run batch 1 on one thread.
//!
//! The ort engine loads the ONNX Runtime shared library given in
//! [`Engine::Ort`]; [`find_ort_library`] finds one in `$ORT_DYLIB_PATH` or in
//! the training venv's onnxruntime wheel. The path is checked before any ort
//! call (ort panics on a missing library), and one library is loaded per
//! process.
//!
//! Test fixtures (`fixtures/`) are made without PyTorch by
//! `fixtures/make_fixture.py` (onnx + onnxruntime); `expected.json` holds
//! onnxruntime's outputs, which both engines reproduce to 1e-5. Latency:
//! `cargo bench -p spacepose-inference [--features ort] --bench infer`, on
//! `$SPACEPOSE_MODEL` (shape from the `model.json` beside it) or the fixture.
//!
//! ```no_run
//! use spacepose_inference::{Engine, ModelShape, PoseNet};
//! let shape = ModelShape { image_size: 96, classes: 600 };
//! let mut net = PoseNet::load("model.onnx".as_ref(), Engine::Tract, shape)?;
//! let out = net.infer(&vec![0.0; 96 * 96])?;
//! println!("{:?} {:?}", out.probs.len(), out.pos_offset_m);
//! # Ok::<(), spacepose_inference::InferenceError>(())
//! ```

mod contract;
mod engine;
mod error;
#[cfg(feature = "ort")]
mod ort_engine;
mod posenet;
#[cfg(test)]
mod test_fixtures;
mod tract_engine;

pub use contract::{INPUT_NAME, ModelShape, NetOutput, POS_NAME, PROBS_NAME};
pub use engine::{Engine, ORT_DYLIB_ENV, find_ort_library};
pub use error::InferenceError;
pub use posenet::PoseNet;
