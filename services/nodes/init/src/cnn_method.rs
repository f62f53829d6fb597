//! The seed 004 CNN (`spacepose-cnn`'s estimator) as a [`PoseAcquirer`]:
//! network → Γ_sym → NDT refinement (§III.E) → f_CONV check (seed 002
//! §4.5). Tried first; template matching is the fallback when its check
//! fails.

use crate::error::InitError;
use crate::method::{MethodOutput, PoseAcquirer};
use serde::{Deserialize, Serialize};
use spacepose_cnn::{CnnEstimator, EstimatorConfig};
use spacepose_geometry::Point;
use spacepose_inference::{Engine, find_ort_library};
use spacepose_messages::AcquisitionMethod;
use spacepose_model::Target;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Which engine runs the network.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CnnEngine {
    /// tract-onnx (pure Rust, always built).
    #[default]
    Tract,
    /// ONNX Runtime (needs the `ort` feature and the library).
    Ort,
}

/// `[cnn]` of the init service's TOML.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CnnMethodConfig {
    /// Directory holding `model.onnx` and `model.json`. A relative path is
    /// looked up in the service's working directory, then in the source
    /// tree's root (where `services/core/cnn/models/<target>` is committed).
    /// Absent (the default): the target's own model, see
    /// [`crate::config::InitServiceConfig::cnn_model_dir`].
    pub model_dir: Option<PathBuf>,
    /// The inference engine.
    pub engine: CnnEngine,
    /// ONNX Runtime library for `engine = "ort"`; absent: `$ORT_DYLIB_PATH`
    /// or the training venv's wheel.
    pub ort_library: Option<PathBuf>,
    /// f_MAX (m²): the CNN pose is accepted when `f_CONV <= f_MAX`. It
    /// overrides `estimator.refinement.f_max_m2`.
    pub f_max_m2: f64,
    /// Decoding, minimum points and refinement settings.
    pub estimator: EstimatorConfig,
}

impl Default for CnnMethodConfig {
    fn default() -> Self {
        let estimator = EstimatorConfig::default();
        Self {
            model_dir: None,
            engine: CnnEngine::Tract,
            ort_library: None,
            f_max_m2: estimator.refinement.f_max_m2,
            estimator,
        }
    }
}

impl CnnMethodConfig {
    /// Checks the values that do not need the model.
    pub fn validate(&self) -> Result<(), InitError> {
        if !(self.f_max_m2.is_finite() && self.f_max_m2 > 0.0) {
            return Err(InitError::InvalidConfig(format!(
                "cnn.f_max_m2 = {} must be > 0",
                self.f_max_m2
            )));
        }
        self.estimator
            .refinement
            .validate()
            .map_err(|e| InitError::InvalidConfig(format!("cnn.estimator.refinement: {e}")))
    }

    /// The engine with its library resolved.
    pub fn engine(&self) -> Result<Engine, InitError> {
        match self.engine {
            CnnEngine::Tract => Ok(Engine::Tract),
            CnnEngine::Ort => {
                let library = match &self.ort_library {
                    Some(path) => path.clone(),
                    None => find_ort_library().map_err(|e| build_error(e.to_string()))?,
                };
                Ok(Engine::Ort { library })
            }
        }
    }
}

/// The root of the source tree this crate was compiled from.
fn source_tree() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../..")
}

/// `dir` itself when it exists or is absolute, else `dir` under the source
/// tree's root when it exists there, else `dir` (whose error names it).
pub(crate) fn resolve_model_dir(dir: &Path) -> PathBuf {
    if dir.is_absolute() || dir.exists() {
        return dir.to_path_buf();
    }
    let in_tree = source_tree().join(dir);
    if in_tree.exists() {
        in_tree
    } else {
        dir.to_path_buf()
    }
}

/// The directory of a built-in target's committed model, `rel` (relative
/// to a source tree's root, e.g. `services/core/cnn/models/deos`), found
/// by its `model.json` in the first of: the working directory and its
/// ancestors (a user in the checkout or below it), the executable's
/// directory's ancestors (`target/release/spacepose` of a checkout run from
/// anywhere), and the source tree the binary was built from.
///
/// Decision: look beside the user and the binary before the compile-time
/// path, because a binary outlives its build tree (a build cache shared by
/// several checkouts bakes in whichever one compiled it, and a deleted
/// checkout left the suite without its CNN with only a warning).
///
/// `Err` names every place looked at.
pub(crate) fn find_committed_model(rel: &Path) -> Result<PathBuf, String> {
    let mut roots: Vec<PathBuf> = Vec::new();
    if let Ok(cwd) = std::env::current_dir() {
        roots.extend(cwd.ancestors().map(Path::to_path_buf));
    }
    if let Ok(exe) = std::env::current_exe()
        && let Some(dir) = exe.parent()
    {
        roots.extend(dir.ancestors().map(Path::to_path_buf));
    }
    roots.push(source_tree());
    let candidates: Vec<PathBuf> = roots.iter().map(|r| r.join(rel)).collect();
    candidates
        .iter()
        .find(|d| d.join("model.json").is_file())
        .cloned()
        .ok_or_else(|| {
            format!(
                "no {} in the working directory, the executable's or the build tree's \
                 ancestors ({} places, the build tree's {})",
                rel.display(),
                candidates.len(),
                candidates
                    .last()
                    .map_or(String::new(), |c| c.display().to_string()),
            )
        })
}

fn build_error(reason: String) -> InitError {
    InitError::Build {
        method: AcquisitionMethod::Cnn.as_str(),
        reason,
    }
}

/// The loaded network with its refinement model.
pub struct CnnMethod {
    estimator: CnnEstimator,
}

impl CnnMethod {
    /// Loads the model in `model_dir` (checked against the class table)
    /// and builds the NDT map for `target`.
    pub fn new(
        target: Arc<Target>,
        model_dir: &Path,
        config: &CnnMethodConfig,
    ) -> Result<Self, InitError> {
        config.validate()?;
        let mut estimator = config.estimator.clone();
        estimator.refinement.f_max_m2 = config.f_max_m2;
        let estimator = CnnEstimator::load_with(model_dir, config.engine()?, target, estimator)
            .map_err(|e| build_error(e.to_string()))?;
        Ok(Self { estimator })
    }
}

impl PoseAcquirer for CnnMethod {
    fn method(&self) -> AcquisitionMethod {
        AcquisitionMethod::Cnn
    }

    fn acquire(&self, cloud: &[Point]) -> Result<MethodOutput, InitError> {
        let e = self
            .estimator
            .estimate(cloud)
            .map_err(|e| InitError::Method {
                method: AcquisitionMethod::Cnn.as_str(),
                reason: e.to_string(),
            })?;
        let t = e.time_ms;
        let refinement = match &e.refinement_error {
            Some(err) => format!("refinement failed: {err}"),
            None => format!(
                "hypothesis {} of {} refined, {} NDT iterations, {:.0}% of the points explained{}",
                e.hypothesis + 1,
                e.hypotheses_refined,
                e.ndt_iterations,
                100.0 * e.twins.explained,
                match e.twins.twin {
                    Some(i) => format!(", replaced by its twin {i}"),
                    None => String::new(),
                }
            ),
        };
        Ok(MethodOutput {
            t_sensor_target: e.t_sensor_target,
            f_conv_m2: e.f_conv_m2,
            accepted: e.accepted,
            detail: format!(
                "{} engine, class {} p={:.2}, {refinement}; preprocess {:.1} ms, inference {:.1} ms, refinement {:.1} ms",
                self.estimator.engine(),
                e.top_class,
                e.top_probability,
                t.preprocess,
                t.inference,
                t.refinement
            ),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::find_committed_model;
    use std::path::Path;

    #[test]
    fn the_committed_model_is_found_and_a_missing_one_named() {
        let deos = find_committed_model(Path::new("services/core/cnn/models/deos")).unwrap();
        assert!(deos.join("model.json").is_file(), "{deos:?}");
        let why =
            find_committed_model(Path::new("services/core/cnn/models/no-such-target")).unwrap_err();
        assert!(why.contains("models/no-such-target"), "{why}");
        assert!(why.contains("build tree"), "{why}");
    }
}
