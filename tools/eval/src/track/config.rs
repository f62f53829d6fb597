//! `spacepose track --config FILE`: the services' own configurations, in
//! one TOML file, for the one-process pipeline.

use crate::tracking::SuiteConfigs;
use anyhow::{Context, Result, anyhow};
use serde::Deserialize;
use spacepose_filter_node::FilterServiceConfig;
use spacepose_ingest_node::IngestServiceConfig;
use spacepose_init_node::{InitServiceConfig, MethodKind};
use spacepose_input::InputOptions;
use spacepose_runtime::ServiceConfig;
use spacepose_tracker_node::TrackerServiceConfig;
use std::path::Path;

/// The file: one table per service, as in a deployment descriptor, and
/// how the recording is read. Every table is optional.
#[derive(Debug, Clone, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrackConfig {
    /// How the recording is read (topic, per-point time mapping).
    pub input: InputOptions,
    /// Ingest's configuration.
    pub ingest: IngestServiceConfig,
    /// The tracker's.
    pub tracker: TrackerServiceConfig,
    /// The filter's.
    pub filter: FilterServiceConfig,
    /// Init's.
    pub init: InitServiceConfig,
}

impl Default for TrackConfig {
    /// The suite's defaults; init tries the CNN first and falls back to
    /// template matching, as in `deploy/demo.toml` (a package without a
    /// model acquires by template matching alone).
    fn default() -> Self {
        Self {
            input: InputOptions::default(),
            ingest: IngestServiceConfig::default(),
            tracker: TrackerServiceConfig::default(),
            filter: FilterServiceConfig::default(),
            init: InitServiceConfig {
                methods: vec![MethodKind::Cnn, MethodKind::TemplateMatching],
                ..InitServiceConfig::default()
            },
        }
    }
}

impl TrackConfig {
    /// Reads `path` (or the defaults) and checks every table.
    pub fn load(path: Option<&Path>) -> Result<TrackConfig> {
        let config = match path {
            None => TrackConfig::default(),
            Some(p) => {
                let text = std::fs::read_to_string(p)
                    .with_context(|| format!("reading {}", p.display()))?;
                toml::from_str(&text).with_context(|| format!("parsing {}", p.display()))?
            }
        };
        Ok(config)
    }

    /// Every service takes the target `spec` at `scale`.
    pub fn set_target(&mut self, spec: &str, scale: f64) {
        self.ingest.target = spec.to_owned();
        self.ingest.target_scale = scale;
        self.tracker.target = spec.to_owned();
        self.tracker.target_scale = scale;
        self.init.target = spec.to_owned();
        self.init.target_scale = scale;
    }

    /// Checks every table (NaN fails).
    pub fn validate(&self) -> Result<()> {
        let table = |name: &str, r: Result<(), String>| r.map_err(|e| anyhow!("[{name}] {e}"));
        table("input", self.input.validate())?;
        table("ingest", ServiceConfig::validate(&self.ingest))?;
        table("tracker", ServiceConfig::validate(&self.tracker))?;
        table("filter", ServiceConfig::validate(&self.filter))?;
        table("init", ServiceConfig::validate(&self.init))
    }

    /// The configurations of the suite's ingest, tracker and filter.
    pub fn suite(&self) -> SuiteConfigs {
        SuiteConfigs {
            ingest: self.ingest.clone(),
            tracker: self.tracker.clone(),
            filter: self.filter.clone(),
        }
    }
}
