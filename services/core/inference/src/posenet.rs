//! `PoseNet`: the seed 004 two-head CNN (§III.D) loaded from an ONNX file
//! and checked against the model contract.

use std::path::{Path, PathBuf};

use crate::contract::{self, ModelShape, NetOutput};
use crate::engine::Engine;
use crate::error::InferenceError;
#[cfg(feature = "ort")]
use crate::ort_engine::OrtNet;
use crate::tract_engine::TractNet;

#[derive(Debug)]
enum Backend {
    Tract(TractNet),
    #[cfg(feature = "ort")]
    Ort(OrtNet),
}

/// A loaded pose network: depth image in, class probabilities and position
/// offset out. Batch 1, one thread.
#[derive(Debug)]
pub struct PoseNet {
    path: PathBuf,
    engine: &'static str,
    expect: ModelShape,
    backend: Backend,
}

impl PoseNet {
    /// Loads `path` with `engine` and checks it against the contract and
    /// `expect`: input `depth` [1, 1, N, N], outputs `probs` [1, m] (a
    /// softmax) and `pos` [1, 3]. One warm-up run on an empty image checks
    /// the output shapes and the softmax.
    pub fn load(
        path: &Path,
        engine: Engine,
        expect: ModelShape,
    ) -> Result<PoseNet, InferenceError> {
        expect.validate()?;
        if !engine.is_compiled() {
            return Err(InferenceError::OrtNotCompiled);
        }
        if !path.is_file() {
            return Err(InferenceError::ModelNotFound {
                path: path.to_path_buf(),
            });
        }
        let engine_name = engine.name();
        let backend = match engine {
            Engine::Tract => Backend::Tract(TractNet::load(path, expect)?),
            #[cfg(feature = "ort")]
            Engine::Ort { library } => Backend::Ort(OrtNet::load(path, &library, expect)?),
            #[cfg(not(feature = "ort"))]
            Engine::Ort { .. } => return Err(InferenceError::OrtNotCompiled),
        };
        let mut net = PoseNet {
            path: path.to_path_buf(),
            engine: engine_name,
            expect,
            backend,
        };
        let warm_up = net.infer(&vec![0.0; expect.pixels()])?;
        contract::check_softmax(path, &warm_up)?;
        Ok(net)
    }

    /// One forward pass on an N × N row-major depth image (seed 004 Eq. 3,
    /// values in [0, 1], 0 = empty pixel). Wrong length or a non-finite value
    /// is an error.
    pub fn infer(&mut self, depth: &[f32]) -> Result<NetOutput, InferenceError> {
        contract::check_depth(depth, self.expect)?;
        match &mut self.backend {
            Backend::Tract(net) => net.infer(depth),
            #[cfg(feature = "ort")]
            Backend::Ort(net) => net.infer(depth),
        }
    }

    /// The shape the model was checked against.
    pub fn shape(&self) -> ModelShape {
        self.expect
    }

    /// The engine running the model (`tract` or `ort`).
    pub fn engine(&self) -> &'static str {
        self.engine
    }

    /// The model file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

#[cfg(test)]
#[path = "posenet_tests.rs"]
mod tests;
