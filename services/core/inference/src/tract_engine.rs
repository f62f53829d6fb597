//! The default engine: tract-onnx (pure Rust, runs on the calling thread).

use std::path::{Path, PathBuf};

use tract_onnx::prelude::*;
use tract_onnx::tract_hir::infer::Factoid;

use crate::contract::{self, Dim, ModelShape, NetOutput};
use crate::error::InferenceError;

const ENGINE: &str = "tract";

/// A model optimised for a fixed [1, 1, N, N] input, with its run state kept
/// between calls (no allocation of the plan per inference).
pub(crate) struct TractNet {
    path: PathBuf,
    expect: ModelShape,
    state: TypedSimpleState,
    probs_ix: usize,
    pos_ix: usize,
}

impl std::fmt::Debug for TractNet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TractNet")
            .field("path", &self.path)
            .field("expect", &self.expect)
            .finish_non_exhaustive()
    }
}

fn invalid(path: &Path, e: impl std::fmt::Display) -> InferenceError {
    InferenceError::ModelInvalid {
        path: path.to_path_buf(),
        engine: ENGINE,
        reason: format!("{e:#}"),
    }
}

fn tdim(d: &TDim) -> Dim {
    d.as_i64()
}

impl TractNet {
    /// Parses, checks against the contract, optimises for batch 1.
    pub(crate) fn load(path: &Path, expect: ModelShape) -> Result<Self, InferenceError> {
        let model = tract_onnx::onnx()
            .model_for_path(path)
            .map_err(|e| invalid(path, e))?;
        check_declared_input(path, &model, expect)?;
        let output_names = model
            .output_outlets()
            .map_err(|e| invalid(path, e))?
            .iter()
            .map(|o| {
                model
                    .outlet_label(*o)
                    .unwrap_or(&model.node(o.node).name)
                    .to_owned()
            })
            .collect::<Vec<_>>();
        let (probs_ix, pos_ix) = contract::find_outputs(path, &output_names)?;
        let n = expect.image_size;
        let typed = model
            .with_input_fact(0, f32::fact([1, 1, n, n]).into())
            .and_then(|m| m.into_optimized())
            .map_err(|e| invalid(path, e))?;
        let dims = |ix: usize| -> Result<Vec<Dim>, InferenceError> {
            let fact = typed.output_fact(ix).map_err(|e| invalid(path, e))?;
            Ok(fact.shape.iter().map(tdim).collect())
        };
        contract::check_output_dims(path, &dims(probs_ix)?, &dims(pos_ix)?, expect)?;
        let state = typed
            .into_runnable()
            .and_then(|plan| plan.spawn())
            .map_err(|e| invalid(path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            expect,
            state,
            probs_ix,
            pos_ix,
        })
    }

    /// One forward pass; `depth` already checked (length N × N, finite).
    pub(crate) fn infer(&mut self, depth: &[f32]) -> Result<NetOutput, InferenceError> {
        let n = self.expect.image_size;
        let run_err = |e: TractError| InferenceError::Run {
            path: self.path.clone(),
            engine: ENGINE,
            reason: format!("{e:#}"),
        };
        let input = Tensor::from_shape(&[1, 1, n, n], depth).map_err(run_err)?;
        let outputs = self.state.run(tvec!(input.into())).map_err(run_err)?;
        let slice = |ix: usize| -> Result<&[f32], InferenceError> {
            let value = outputs.get(ix).ok_or_else(|| InferenceError::Run {
                path: self.path.clone(),
                engine: ENGINE,
                reason: format!("output {ix} missing"),
            })?;
            value
                .try_as_plain_ram()
                .and_then(|v| v.as_slice::<f32>())
                .map_err(run_err)
        };
        contract::output_from_slices(
            &self.path,
            slice(self.probs_ix)?,
            slice(self.pos_ix)?,
            self.expect,
        )
    }
}

/// The input as the file declares it, before it is fixed to [1, 1, N, N].
fn check_declared_input(
    path: &Path,
    model: &InferenceModel,
    expect: ModelShape,
) -> Result<(), InferenceError> {
    let inputs = model.input_outlets().map_err(|e| invalid(path, e))?;
    let names: Vec<String> = inputs
        .iter()
        .map(|o| model.node(o.node).name.clone())
        .collect();
    if names.len() != 1 {
        // Fails on the names, with the contract's message.
        return contract::check_input(path, &names, true, "?", &[], expect);
    }
    let fact = model.input_fact(0).map_err(|e| invalid(path, e))?;
    let dtype = fact.datum_type.concretize();
    // An undeclared type is accepted: the optimiser then runs it as float32.
    let is_f32 = dtype.is_none_or(|t| t == f32::datum_type());
    let dtype = dtype.map_or_else(|| "?".to_owned(), |t| format!("{t:?}"));
    let dims: Vec<Dim> = fact
        .shape
        .dims()
        .map(|d| d.concretize().and_then(|t| tdim(&t)))
        .collect();
    contract::check_input(path, &names, is_f32, &dtype, &dims, expect)
}
