//! The optional engine: ONNX Runtime through `ort`, library loaded at run
//! time (`load-dynamic`). ort panics when no library can be loaded, so the
//! path is checked and loaded explicitly here before any other ort call.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use ort::environment::Environment;
use ort::session::Session;
use ort::value::{TensorElementType, TensorRef, ValueType};

use crate::contract::{self, Dim, INPUT_NAME, ModelShape, NetOutput, POS_NAME, PROBS_NAME};
use crate::error::InferenceError;

const ENGINE: &str = "ort";

/// ONNX Runtime allows one library and one environment per process: the
/// library path loaded first and its environment, shared by every session.
static RUNTIME: Mutex<Option<(PathBuf, Environment)>> = Mutex::new(None);

/// The process-wide environment, loading `library` on first use.
fn environment(library: &Path) -> Result<Environment, InferenceError> {
    if !library.is_file() {
        return Err(InferenceError::OrtLibraryNotFound {
            path: library.to_path_buf(),
        });
    }
    let requested = library
        .canonicalize()
        .unwrap_or_else(|_| library.to_path_buf());
    let mut runtime = RUNTIME
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    if let Some((loaded, env)) = runtime.as_ref() {
        return if *loaded == requested {
            Ok(env.clone())
        } else {
            Err(InferenceError::OrtLibraryConflict {
                loaded: loaded.clone(),
                requested,
            })
        };
    }
    let load_err = |reason: String| InferenceError::OrtLibraryLoad {
        path: requested.clone(),
        reason,
    };
    let env = ort::init_from(&requested)
        .map_err(|e| load_err(e.to_string()))?
        .with_name("spacepose-inference")
        .build()
        .map_err(|e| load_err(e.to_string()))?;
    *runtime = Some((requested, env.clone()));
    Ok(env)
}

/// An ONNX Runtime session with one intra-op thread.
pub(crate) struct OrtNet {
    path: PathBuf,
    expect: ModelShape,
    session: Session,
}

impl std::fmt::Debug for OrtNet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OrtNet")
            .field("path", &self.path)
            .field("expect", &self.expect)
            .finish_non_exhaustive()
    }
}

fn invalid(path: &Path, e: impl std::fmt::Display) -> InferenceError {
    InferenceError::ModelInvalid {
        path: path.to_path_buf(),
        engine: ENGINE,
        reason: e.to_string(),
    }
}

/// Element type and dimensions (`-1` = dynamic) of a declared tensor.
fn tensor_info(dtype: &ValueType) -> (Option<TensorElementType>, Vec<Dim>) {
    let dims = dtype
        .tensor_shape()
        .map(|s| s.iter().map(|d| (*d >= 0).then_some(*d)).collect())
        .unwrap_or_default();
    (dtype.tensor_type(), dims)
}

impl OrtNet {
    /// Loads the library (once per process), opens a session, checks the
    /// declared input and outputs against the contract.
    pub(crate) fn load(
        path: &Path,
        library: &Path,
        expect: ModelShape,
    ) -> Result<Self, InferenceError> {
        let env = environment(library)?;
        let session = Session::builder(&env)
            .and_then(|b| b.with_intra_threads(1).map_err(Into::into))
            .and_then(|b| b.with_inter_threads(1).map_err(Into::into))
            .and_then(|b| b.with_parallel_execution(false).map_err(Into::into))
            .and_then(|mut b| b.commit_from_file(path))
            .map_err(|e| invalid(path, e))?;

        let input_names: Vec<String> = session
            .inputs()
            .iter()
            .map(|o| o.name().to_owned())
            .collect();
        let (ty, dims) = session
            .inputs()
            .first()
            .map(|o| tensor_info(o.dtype()))
            .unwrap_or_default();
        let dtype = ty.map_or_else(|| "non-tensor".to_owned(), |t| format!("{t:?}"));
        contract::check_input(
            path,
            &input_names,
            ty == Some(TensorElementType::Float32),
            &dtype,
            &dims,
            expect,
        )?;

        let output_names: Vec<String> = session
            .outputs()
            .iter()
            .map(|o| o.name().to_owned())
            .collect();
        let (probs_ix, pos_ix) = contract::find_outputs(path, &output_names)?;
        let dims = |ix: usize| tensor_info(session.outputs()[ix].dtype()).1;
        contract::check_output_dims(path, &dims(probs_ix), &dims(pos_ix), expect)?;
        Ok(Self {
            path: path.to_path_buf(),
            expect,
            session,
        })
    }

    /// One forward pass; `depth` already checked (length N × N, finite).
    pub(crate) fn infer(&mut self, depth: &[f32]) -> Result<NetOutput, InferenceError> {
        let n = self.expect.image_size;
        let path = &self.path;
        let run_err = |e: ort::Error| InferenceError::Run {
            path: path.clone(),
            engine: ENGINE,
            reason: e.to_string(),
        };
        let input = TensorRef::from_array_view(([1usize, 1, n, n], depth)).map_err(run_err)?;
        let outputs = self
            .session
            .run(ort::inputs![INPUT_NAME => input])
            .map_err(run_err)?;
        let slice = |name: &str| -> Result<&[f32], InferenceError> {
            let value = outputs.get(name).ok_or_else(|| InferenceError::Run {
                path: path.clone(),
                engine: ENGINE,
                reason: format!("output `{name}` missing"),
            })?;
            value
                .try_extract_tensor::<f32>()
                .map(|(_, data)| data)
                .map_err(run_err)
        };
        contract::output_from_slices(path, slice(PROBS_NAME)?, slice(POS_NAME)?, self.expect)
    }
}

#[cfg(test)]
#[path = "ort_engine_tests.rs"]
mod tests;
