//! The init service's TOML configuration (keys in
//! `deploy/examples/init.toml`), and the method chain it describes.

use crate::chain::MethodChain;
use crate::cnn_method::{CnnMethod, CnnMethodConfig, find_committed_model, resolve_model_dir};
use crate::error::InitError;
use crate::method::PoseAcquirer;
use crate::state::InitConfig;
use crate::template::TemplateMatching;
use crate::verify::{Verifier, VerifyConfig};
use serde::{Deserialize, Serialize};
use spacepose_acquisition::TemplateMatchingConfig;
use spacepose_cnn::model_meta::ModelMeta;
use spacepose_lidar_sim::SensorConfig;
use spacepose_messages::Name;
use spacepose_model::Target;
use spacepose_model::package::TargetPackage;
use spacepose_runtime::ServiceConfig;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// An acquisition method the service can run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MethodKind {
    /// Seed 002 on-line template matching + ICP + f_CONV check.
    TemplateMatching,
    /// Seed 004 CNN + NDT refinement + f_CONV check (issue 6).
    Cnn,
}

/// The init service's TOML file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct InitServiceConfig {
    /// Target: a built-in name (`"deos"`, `"envisat"`), a package directory
    /// (`spacepose target prepare`) or a mesh file (prepared on first use).
    pub target: String,
    /// Scale applied to a mesh file.
    pub target_scale: f64,
    /// Integration time of the sensor whose scan pattern the templates use
    /// (s; the Livox Mid-40 model, as lidar-sim).
    pub integration_time_s: f64,
    /// Instance name; `--instance` overrides it; default `"init"`.
    pub instance: Option<String>,
    /// Methods tried in order on each frame; the first accepted pose wins
    /// (issue 6 will put the CNN first, template matching as the fallback).
    pub methods: Vec<MethodKind>,
    /// A frame with fewer finite points (after the voxel filter) is a
    /// failure without trying any method (seed 002's sparse-cloud case).
    pub min_points: usize,
    /// Voxel edge of the cloud the methods see (m, seed 000 §3.3; 0: the
    /// cropped points as they are). 2 cm, the filter ingest applied before
    /// the voxel filter moved behind the tracker's motion compensation.
    pub leaf_size_m: f64,
    /// When to acquire, retry and give up on a hand-over.
    pub state: InitConfig,
    /// Template matching, refinement and f_MAX.
    pub template_matching: TemplateMatchingConfig,
    /// The CNN: model directory, engine, f_MAX, refinement.
    pub cnn: CnnMethodConfig,
    /// While the suite tracks: acquisitions on later frames against the
    /// tracker's poses (`crate::verify`).
    pub verify: VerifyConfig,
}

impl Default for InitServiceConfig {
    fn default() -> Self {
        Self {
            target: "deos".into(),
            target_scale: 1.0,
            integration_time_s: SensorConfig::MID40_INTEGRATION_TIME_S,
            instance: None,
            methods: vec![MethodKind::TemplateMatching],
            min_points: 20,
            leaf_size_m: 0.02,
            state: InitConfig::default(),
            template_matching: TemplateMatchingConfig::default(),
            cnn: CnnMethodConfig::default(),
            verify: VerifyConfig::default(),
        }
    }
}

impl InitServiceConfig {
    /// Checks every value (NaN fails) and that every method is available.
    pub fn validate(&self) -> Result<(), InitError> {
        let bad = |m: String| Err(InitError::InvalidConfig(m));
        if self.target.is_empty() {
            return bad("target must not be empty".into());
        }
        if !(self.target_scale.is_finite() && self.target_scale > 0.0) {
            return bad(format!("target_scale = {} must be > 0", self.target_scale));
        }
        if !(self.integration_time_s.is_finite() && self.integration_time_s > 0.0) {
            return bad(format!(
                "integration_time_s = {} must be > 0",
                self.integration_time_s
            ));
        }
        if let Some(instance) = &self.instance {
            Name::new(instance).map_err(|e| InitError::InvalidConfig(format!("instance: {e}")))?;
        }
        if self.methods.is_empty() {
            return bad("methods must list at least one method".into());
        }
        if self.methods.contains(&MethodKind::Cnn) {
            self.cnn.validate()?;
        }
        if !(self.leaf_size_m.is_finite() && self.leaf_size_m >= 0.0) {
            return bad(format!("leaf_size_m = {} must be >= 0", self.leaf_size_m));
        }
        if self.min_points < 3 {
            return bad(format!("min_points = {} must be >= 3", self.min_points));
        }
        self.state.validate()?;
        self.verify
            .validate()
            .map_err(|e| InitError::InvalidConfig(format!("verify: {e}")))?;
        self.template_matching
            .validate()
            .map_err(|e| InitError::InvalidConfig(format!("template_matching: {e}")))
    }

    /// The sensor model the templates are cast with.
    pub fn sensor(&self) -> SensorConfig {
        SensorConfig {
            integration_time_s: self.integration_time_s,
            ..SensorConfig::livox_mid40()
        }
    }

    /// Resolves the target and builds every configured method, in order.
    pub fn build_chain(&self) -> Result<MethodChain, InitError> {
        self.build().map(|(chain, _)| chain)
    }

    /// Resolves the target once; builds the method chain and the verifier
    /// of the hand-overs (the target's symmetries and size).
    pub fn build(&self) -> Result<(MethodChain, Verifier), InitError> {
        let package = spacepose_prepare::resolve(&self.target, self.target_scale)
            .map_err(|e| InitError::InvalidConfig(format!("target {:?}: {e}", self.target)))?;
        let target = Arc::new(package.target.clone());
        let verifier = Verifier::new(
            self.verify.clone(),
            target.symmetries().to_vec(),
            target.bounding_radius(),
        );
        Ok((self.build_methods(&package, target)?, verifier))
    }

    /// Every configured method, in order, on the resolved `target`.
    fn build_methods(
        &self,
        package: &TargetPackage,
        target: Arc<Target>,
    ) -> Result<MethodChain, InitError> {
        let mut methods: Vec<Box<dyn PoseAcquirer>> = Vec::new();
        for kind in &self.methods {
            match kind {
                MethodKind::TemplateMatching => methods.push(Box::new(TemplateMatching::new(
                    target.clone(),
                    self.sensor(),
                    self.template_matching.clone(),
                )?)),
                MethodKind::Cnn => match self.cnn_model_dir(package) {
                    Ok(dir) => {
                        tracing::info!(target = target.name(), "CNN model from {}", dir.display());
                        methods.push(Box::new(CnnMethod::new(target.clone(), &dir, &self.cnn)?));
                    }
                    Err(why) if self.methods.contains(&MethodKind::TemplateMatching) => {
                        tracing::warn!(
                            target = target.name(),
                            "no CNN for this target ({why}): acquiring by template matching alone"
                        );
                    }
                    Err(why) => {
                        return Err(InitError::InvalidConfig(format!(
                            "no CNN for target {} ({why}) and template matching is not configured",
                            target.name()
                        )));
                    }
                },
            }
        }
        MethodChain::new(methods, self.min_points)?.with_voxels(self.leaf_size_m)
    }
}

impl InitServiceConfig {
    /// The CNN model directory for `package`:
    /// - `cnn.model_dir` when configured; a missing or broken directory is
    ///   returned as it is, for the loader to report as a configuration
    ///   error (a mistyped path must not turn into a silent fallback);
    /// - else the package's own model (`DIR/cnn`, written by
    ///   `spacepose train --target DIR`);
    /// - else, for a built-in target, its model committed in the source
    ///   tree (`services/core/cnn/models/<name>`), looked for beside the
    ///   working directory, the executable and the build tree
    ///   ([`find_committed_model`]).
    ///
    /// `Err(why)` when there is no model for this target, or the model
    /// found was trained for another one: template matching then acquires
    /// alone, if configured.
    pub fn cnn_model_dir(&self, package: &TargetPackage) -> Result<PathBuf, String> {
        let name = package.target.name();
        let dir = match &self.cnn.model_dir {
            Some(dir) => resolve_model_dir(dir),
            None => match package.cnn_dir() {
                Some(dir) => dir,
                None => find_committed_model(&Path::new("services/core/cnn/models").join(name))
                    .map_err(|why| {
                        format!(
                            "the package has no model, and there is {why}; `spacepose train \
                             --target DIR` trains one into a package directory"
                        )
                    })?,
            },
        };
        match ModelMeta::read(&dir) {
            Ok(meta) if meta.target != name => Err(format!(
                "the model in {} was trained for {}",
                dir.display(),
                meta.target
            )),
            _ => Ok(dir),
        }
    }
}

/// `spacepose-init --config FILE`.
impl ServiceConfig for InitServiceConfig {
    fn validate(&self) -> Result<(), String> {
        InitServiceConfig::validate(self).map_err(|e| e.to_string())
    }

    fn instance(&self) -> Option<&str> {
        self.instance.as_deref()
    }
}

#[cfg(test)]
#[path = "config_tests.rs"]
mod tests;
