//! The init service's TOML configuration (keys in
//! `deploy/examples/init.toml`), and the method chain it describes.

use crate::chain::MethodChain;
use crate::cnn_method::{CnnMethod, CnnMethodConfig};
use crate::error::InitError;
use crate::method::PoseAcquirer;
use crate::state::InitConfig;
use crate::template::TemplateMatching;
use serde::{Deserialize, Serialize};
use spacepose_acquisition::TemplateMatchingConfig;
use spacepose_lidar_sim::SensorConfig;
use spacepose_messages::Name;
use spacepose_runtime::ServiceConfig;
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
        let target = spacepose_prepare::resolve(&self.target, self.target_scale)
            .map_err(|e| InitError::InvalidConfig(format!("target {:?}: {e}", self.target)))?
            .target;
        let target = Arc::new(target);
        let mut methods: Vec<Box<dyn PoseAcquirer>> = Vec::new();
        for kind in &self.methods {
            match kind {
                MethodKind::TemplateMatching => methods.push(Box::new(TemplateMatching::new(
                    target.clone(),
                    self.sensor(),
                    self.template_matching.clone(),
                )?)),
                MethodKind::Cnn => match self.cnn_unavailable(target.name()) {
                    Some(why) if self.methods.contains(&MethodKind::TemplateMatching) => {
                        tracing::warn!(
                            target = target.name(),
                            "no CNN for this target ({why}): acquiring by template matching alone"
                        );
                    }
                    _ => methods.push(Box::new(CnnMethod::new(target.clone(), &self.cnn)?)),
                },
            }
        }
        MethodChain::new(methods, self.min_points)?.with_voxels(self.leaf_size_m)
    }
}

impl InitServiceConfig {
    /// Why the configured CNN cannot serve `target`: its model was trained
    /// for another target. `None` otherwise: a missing or broken model is
    /// a configuration error the loader reports and the service stops on
    /// (a mistyped `model_dir` must not turn into a silent fallback).
    pub fn cnn_unavailable(&self, target: &str) -> Option<String> {
        let dir = crate::cnn_method::resolve_model_dir(&self.cnn.model_dir);
        match spacepose_cnn::model_meta::ModelMeta::read(&dir) {
            Ok(meta) if meta.target != target => Some(format!(
                "the model in {} was trained for {}",
                dir.display(),
                meta.target
            )),
            _ => None,
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
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_round_trip_through_toml() {
        let c = InitServiceConfig::default();
        c.validate().unwrap();
        let text = toml::to_string(&c).unwrap();
        let back: InitServiceConfig = toml::from_str(&text).unwrap();
        assert_eq!(back, c);
    }

    /// `deploy/examples/init.toml` parses, and so does its commented
    /// `[template_matching]` example once uncommented.
    #[test]
    fn the_deploy_example_parses() {
        let text = include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../deploy/examples/init.toml"
        ));
        let c: InitServiceConfig = toml::from_str(text).unwrap();
        c.validate().unwrap();
        let uncommented: String = text
            .lines()
            .map(|l| match l.strip_prefix("# ") {
                Some(rest) if rest.starts_with("[template_matching") || rest.contains(" = ") => {
                    rest.split('#').next().unwrap_or("").trim_end()
                }
                _ => l,
            })
            .collect::<Vec<_>>()
            .join("\n");
        let c: InitServiceConfig = toml::from_str(&uncommented).unwrap();
        c.validate().unwrap();
        assert_eq!(c.template_matching.u_max, 0.3);
        assert_eq!(c.template_matching.icp.max_iterations, 40);
        assert_eq!(
            c.template_matching.far_lookup,
            TemplateMatchingConfig::default().far_lookup
        );
    }

    /// The file's `instance` is the instance name unless `--instance` is
    /// given; the trait's validation is the config's.
    #[test]
    fn the_instance_key_names_the_instance() {
        let c: InitServiceConfig = toml::from_str("instance = \"init-b\"\n").unwrap();
        assert_eq!(ServiceConfig::instance(&c), Some("init-b"));
        assert_eq!(ServiceConfig::instance(&InitServiceConfig::default()), None);
        let bad: InitServiceConfig = toml::from_str("instance = \"bad name!\"\n").unwrap();
        let e = ServiceConfig::validate(&bad).unwrap_err();
        assert!(e.contains("instance"), "{e}");
        assert!(ServiceConfig::validate(&c).is_ok());
    }

    #[test]
    fn partial_files_take_defaults_and_unknown_keys_fail() {
        let c: InitServiceConfig =
            toml::from_str("target = \"deos\"\n[state]\nretry_after_frames = 2\n").unwrap();
        assert_eq!(c.state.retry_after_frames, 2);
        assert_eq!(
            c.state.handover_frames,
            InitConfig::default().handover_frames
        );
        assert!(toml::from_str::<InitServiceConfig>("targett = \"deos\"").is_err());
        assert!(toml::from_str::<InitServiceConfig>("[state]\nretry = 1").is_err());
        // The matcher's and its ICP's sections are partial too.
        let c: InitServiceConfig = toml::from_str(
            "[template_matching]\nu_max = 0.4\n[template_matching.icp]\nmax_iterations = 30\n",
        )
        .unwrap();
        assert_eq!(c.template_matching.u_max, 0.4);
        assert_eq!(c.template_matching.icp.max_iterations, 30);
        assert_eq!(
            c.template_matching.delta_deg,
            TemplateMatchingConfig::default().delta_deg
        );
        assert!(toml::from_str::<InitServiceConfig>("[template_matching]\numax = 0.4").is_err());
    }

    #[test]
    fn nan_zero_and_unavailable_values_fail_validation() {
        let base = InitServiceConfig::default();
        let mut tm_nan = base.template_matching.clone();
        tm_nan.f_max_m2 = f64::NAN;
        for c in [
            InitServiceConfig {
                target_scale: f64::NAN,
                ..base.clone()
            },
            InitServiceConfig {
                integration_time_s: f64::NAN,
                ..base.clone()
            },
            InitServiceConfig {
                integration_time_s: 0.0,
                ..base.clone()
            },
            InitServiceConfig {
                methods: vec![],
                ..base.clone()
            },
            InitServiceConfig {
                methods: vec![MethodKind::Cnn, MethodKind::TemplateMatching],
                cnn: CnnMethodConfig {
                    f_max_m2: f64::NAN,
                    ..CnnMethodConfig::default()
                },
                ..base.clone()
            },
            InitServiceConfig {
                min_points: 2,
                ..base.clone()
            },
            InitServiceConfig {
                instance: Some("bad name!".into()),
                ..base.clone()
            },
            InitServiceConfig {
                template_matching: tm_nan,
                ..base.clone()
            },
        ] {
            assert!(c.validate().is_err(), "{c:?}");
        }
    }

    #[test]
    fn a_target_without_a_cnn_acquires_by_template_matching_alone() {
        let both = InitServiceConfig {
            target: "envisat".into(),
            methods: vec![MethodKind::Cnn, MethodKind::TemplateMatching],
            ..InitServiceConfig::default()
        };
        let why = both
            .cnn_unavailable("envisat")
            .expect("the model is deos's");
        assert!(why.contains("trained for deos"), "{why}");
        assert_eq!(both.cnn_unavailable("deos"), None);
        let chain = both.build_chain().expect("template matching alone");
        let tm = spacepose_messages::AcquisitionMethod::TemplateMatching;
        assert_eq!(chain.methods(), vec![tm]);

        let cnn_only = InitServiceConfig {
            methods: vec![MethodKind::Cnn],
            ..both.clone()
        };
        let e = cnn_only.build_chain().err().expect("no method left");
        assert!(e.to_string().contains("deos"), "{e}");

        let missing = InitServiceConfig {
            cnn: CnnMethodConfig {
                model_dir: "/nonexistent/model".into(),
                ..CnnMethodConfig::default()
            },
            ..both
        };
        assert_eq!(missing.cnn_unavailable("envisat"), None, "a config error");
        let e = missing
            .build_chain()
            .err()
            .expect("a missing model stops init");
        assert!(e.to_string().contains("/nonexistent/model"), "{e}");
    }
}
