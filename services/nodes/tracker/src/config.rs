//! Configuration of the `spacepose-tracker` service and the model it loads
//! (keys in `deploy/examples/tracker.toml`).

use serde::{Deserialize, Serialize};
use spacepose_messages::{MAX_POINTS, Name};
use spacepose_registration::{NdtMap, NdtMapParams};
use spacepose_runtime::ServiceConfig;
use spacepose_tracker::{
    TargetThresholds, TrackError, TrackerConfig, TrackingModel, map_params_scaled,
};
use std::path::{Path, PathBuf};

/// The tracker service's TOML file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrackerServiceConfig {
    /// Target: a built-in name (`"deos"`, `"envisat"`), a package
    /// directory (`spacepose target prepare`), or a mesh file (STL/OBJ/PLY,
    /// prepared into the cache on first use).
    pub target: String,
    /// Scale applied to a mesh file (e.g. 0.001 for a model in mm).
    pub target_scale: f64,
    /// Spacing of the model cloud sampled on the target surface (m), for
    /// the reference 7.5 cm cell: multiplied by the target's ℓ / 7.5 cm
    /// (`spacepose_tracker::length_unit`; 1 for deos).
    pub model_spacing_m: f64,
    /// Seed of the surface sampling.
    pub model_seed: u64,
    /// NDT map file: loaded when it exists, otherwise built from the model
    /// cloud (default `NdtMapParams`) and saved there on first start. A file
    /// that cannot be read, is corrupt or was built with other parameters is
    /// an error (delete it to rebuild, e.g. after changing the target).
    pub map_file: Option<PathBuf>,
    /// Instance name (e.g. `"tracker-a"`); `--instance` overrides it;
    /// default `"tracker"`.
    pub instance: Option<String>,
    /// Largest frame accepted (points); larger frames are rejected and counted.
    pub max_points: usize,
    /// The tracking loop (mode, registration, filter, loss thresholds).
    pub tracker: TrackerConfig,
}

impl Default for TrackerServiceConfig {
    fn default() -> Self {
        Self {
            target: "deos".to_string(),
            target_scale: 1.0,
            model_spacing_m: 0.015,
            model_seed: 0,
            map_file: None,
            instance: None,
            max_points: MAX_POINTS,
            tracker: TrackerConfig::default(),
        }
    }
}

/// Where the NDT map of a [`TrackingModel`] came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MapSource {
    /// Built in memory (no `map_file`).
    Built,
    /// Built and saved to the file (first start).
    BuiltAndSaved(PathBuf),
    /// Loaded from the file.
    Loaded(PathBuf),
}

impl ServiceConfig for TrackerServiceConfig {
    /// Checks every value (NaN fails); the message names the key.
    fn validate(&self) -> Result<(), String> {
        let bad = |m: String| Err(m);
        if self.target.is_empty() {
            return bad("target must not be empty".into());
        }
        if !(self.target_scale.is_finite() && self.target_scale > 0.0) {
            return bad(format!("target_scale = {} must be > 0", self.target_scale));
        }
        if !(self.model_spacing_m.is_finite() && self.model_spacing_m > 0.0) {
            return bad(format!(
                "model_spacing_m = {} must be > 0",
                self.model_spacing_m
            ));
        }
        if !(1..=MAX_POINTS).contains(&self.max_points) {
            return bad(format!(
                "max_points = {} must be in 1..={MAX_POINTS}",
                self.max_points
            ));
        }
        if let Some(instance) = &self.instance {
            Name::new(instance).map_err(|e| format!("instance: {e}"))?;
        }
        self.tracker.validate().map_err(|e| e.to_string())
    }

    /// The `instance` key (`--instance` wins over it).
    fn instance(&self) -> Option<&str> {
        self.instance.as_deref()
    }
}

impl TrackerServiceConfig {
    /// Resolves the target, samples its model cloud, and builds (or loads)
    /// the NDT map (seed 000 §3.1); the ICP model is built on first use
    /// (`TrackingModel::icp`), at start only in `icp` mode.
    pub fn build_model(&self) -> Result<(TrackingModel, MapSource), TrackError> {
        let package = spacepose_prepare::resolve(&self.target, self.target_scale)
            .map_err(|e| TrackError::Model(format!("target {:?}: {e}", self.target)))?;
        let thresholds = TargetThresholds::from(&package.manifest.calibration);
        let factor = thresholds.length_scale;
        let model_target = package
            .target
            .sample_surface(self.model_spacing_m * factor, self.model_seed);
        let params = map_params_scaled(factor);
        let Some(path) = &self.map_file else {
            return Ok((
                TrackingModel::build(&model_target, &params)?.with_thresholds(thresholds),
                MapSource::Built,
            ));
        };
        if path.exists() {
            let map = load_map(path, &params)?;
            return Ok((
                TrackingModel::from_map(map, &model_target).with_thresholds(thresholds),
                MapSource::Loaded(path.clone()),
            ));
        }
        let model = TrackingModel::build(&model_target, &params)?.with_thresholds(thresholds);
        model
            .map
            .save(path)
            .map_err(|e| TrackError::Model(format!("saving the NDT map: {e}")))?;
        Ok((model, MapSource::BuiltAndSaved(path.clone())))
    }
}

fn load_map(path: &Path, params: &NdtMapParams) -> Result<NdtMap, TrackError> {
    let map = NdtMap::load(path).map_err(|e| TrackError::Model(e.to_string()))?;
    if map.params() != params {
        return Err(TrackError::Model(format!(
            "{} was built with other map parameters (delete it to rebuild)",
            path.display()
        )));
    }
    Ok(map)
}

#[cfg(test)]
mod tests {
    use super::*;
    use spacepose_tracker::TrackingMode;

    #[test]
    fn defaults_are_valid_and_bad_values_are_named() {
        TrackerServiceConfig::default().validate().unwrap();
        let cases = [
            (
                "target_scale",
                TrackerServiceConfig {
                    target_scale: f64::NAN,
                    ..Default::default()
                },
            ),
            (
                "model_spacing_m",
                TrackerServiceConfig {
                    model_spacing_m: 0.0,
                    ..Default::default()
                },
            ),
            (
                "max_points",
                TrackerServiceConfig {
                    max_points: MAX_POINTS + 1,
                    ..Default::default()
                },
            ),
            (
                "instance",
                TrackerServiceConfig {
                    instance: Some("a b".into()),
                    ..Default::default()
                },
            ),
        ];
        for (what, c) in cases {
            let e = c.validate().unwrap_err().to_string();
            assert!(e.contains(what), "{what}: {e}");
        }
        let named = TrackerServiceConfig {
            instance: Some("tracker-a".into()),
            ..Default::default()
        };
        assert_eq!(named.instance(), Some("tracker-a"));
        assert_eq!(TrackerServiceConfig::default().instance(), None);
    }

    #[test]
    fn toml_is_strict_and_partial() {
        let c: TrackerServiceConfig = toml::from_str(
            "target = \"envisat\"\nmap_file = \"/tmp/x.ndt\"\n[tracker]\nmode = \"ct-ndt\"\n",
        )
        .unwrap();
        assert_eq!(c.target, "envisat");
        assert_eq!(c.tracker.mode, TrackingMode::CtNdt);
        assert_eq!(c.max_points, MAX_POINTS);
        assert!(toml::from_str::<TrackerServiceConfig>("targte = \"deos\"\n").is_err());
        assert!(toml::from_str::<TrackerServiceConfig>("[tracker]\nmod = \"ndt\"\n").is_err());
    }

    /// The documented example parses, validates and shows the defaults.
    #[test]
    fn the_deploy_example_is_valid() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../deploy/examples/tracker.toml"
        );
        let text = std::fs::read_to_string(path).unwrap();
        let c: TrackerServiceConfig = toml::from_str(&text).unwrap();
        c.validate().unwrap();
        let d = TrackerConfig::default();
        assert_eq!(c.tracker.ct_start, d.ct_start);
        assert_eq!(c.tracker.release_lever_arm_m, d.release_lever_arm_m);
        assert_eq!(
            c.tracker.ct_ndt_attitude_covariance_scale,
            d.ct_ndt_attitude_covariance_scale
        );
        // Its commented [tracker.filter] section, uncommented, keeps the
        // default innovation gate (absent = the default).
        let uncommented = text
            .replace("# [tracker.filter]", "[tracker.filter]")
            .replace("# q_pos = 1e-4", "q_pos = 1e-4");
        let c: TrackerServiceConfig = toml::from_str(&uncommented).unwrap();
        assert_eq!(c.tracker.filter.q_pos, 1e-4);
        assert_eq!(
            c.tracker.filter.gate_mahalanobis2,
            spacepose_filter::FilterConfig::default().gate_mahalanobis2
        );
    }

    #[test]
    fn unknown_targets_and_corrupt_maps_are_errors() {
        let c = TrackerServiceConfig {
            target: "no-such-target.stl".into(),
            ..Default::default()
        };
        assert!(matches!(c.build_model(), Err(TrackError::Model(_))));
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("corrupt.ndt");
        std::fs::write(&path, b"not a map").unwrap();
        let c = TrackerServiceConfig {
            map_file: Some(path),
            ..Default::default()
        };
        assert!(matches!(c.build_model(), Err(TrackError::Model(_))));
    }
}
