//! Configuration of the `spacepose-ingest` service (keys in
//! `deploy/examples/ingest.toml`): the crop stage's settings, with the
//! target's region (bounding radius, body box) taken from its package
//! unless the file sets them.

use serde::Deserialize;
use spacepose_ingest::{AxisBox, DetectConfig, IngestConfig};
use spacepose_runtime::ServiceConfig;

/// `spacepose-ingest --config FILE`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IngestServiceConfig {
    /// Target: a built-in name, a package directory or a mesh file (as for
    /// the tracker and init); its package gives the region below.
    pub target: String,
    /// Scale of a mesh file (file units → metres).
    pub target_scale: f64,
    /// Range gate, lower bound (m).
    pub min_range_m: f64,
    /// Range gate, upper bound (m).
    pub max_range_m: f64,
    /// Radius of the sphere about the centre of mass that holds the target
    /// (m). Unset (the default): the package's bounding radius.
    pub target_bounding_radius_m: Option<f64>,
    /// Added to the bounding radius and to the body box (m).
    pub margin_m: f64,
    /// A prediction older than this at scan end (s) is not trusted.
    pub max_prediction_age_s: f64,
    /// Largest accepted frame (points).
    pub max_points: usize,
    /// Fewer points than this after the crop count as "target not seen".
    pub min_target_points: usize,
    /// Region used before acquisition (sensor frame), if any.
    pub static_box: Option<AxisBox>,
    /// The target's box in its body frame. Unset (the default): the
    /// package's body box.
    pub body_box: Option<AxisBox>,
    /// `false` crops with the sphere alone (no body box).
    pub use_body_box: bool,
    /// Finding the target in a frame without a prediction (the `[detect]`
    /// table: `spacepose_ingest::DetectConfig`).
    pub detect: DetectConfig,
}

impl Default for IngestServiceConfig {
    /// Target `deos`; the crop stage's defaults for every other key.
    fn default() -> Self {
        let c = IngestConfig::default();
        IngestServiceConfig {
            target: "deos".to_owned(),
            target_scale: 1.0,
            min_range_m: c.min_range_m,
            max_range_m: c.max_range_m,
            target_bounding_radius_m: None,
            margin_m: c.margin_m,
            max_prediction_age_s: c.max_prediction_age_s,
            max_points: c.max_points,
            min_target_points: c.min_target_points,
            static_box: c.static_box,
            body_box: None,
            use_body_box: true,
            detect: c.detect,
        }
    }
}

impl IngestServiceConfig {
    /// The crop stage's configuration with this region.
    fn with_region(&self, radius_m: f64, body_box: Option<AxisBox>) -> IngestConfig {
        IngestConfig {
            min_range_m: self.min_range_m,
            max_range_m: self.max_range_m,
            target_bounding_radius_m: radius_m,
            margin_m: self.margin_m,
            max_prediction_age_s: self.max_prediction_age_s,
            max_points: self.max_points,
            min_target_points: self.min_target_points,
            static_box: self.static_box,
            body_box: body_box.filter(|_| self.use_body_box),
            detect: self.detect.clone(),
        }
    }

    /// The crop stage's configuration: the region keys the file leaves
    /// unset come from the target's package (resolved, and prepared on
    /// first use for a mesh file).
    pub fn crop_config(&self) -> anyhow::Result<IngestConfig> {
        let needs_package = self.target_bounding_radius_m.is_none()
            || (self.use_body_box && self.body_box.is_none());
        let (radius_m, body_box) = if needs_package {
            let package = spacepose_prepare::resolve(&self.target, self.target_scale)
                .map_err(|e| anyhow::anyhow!("target {:?}: {e}", self.target))?;
            let g = &package.manifest.geometry;
            let package_box = AxisBox {
                min_m: g.body_box_min_m,
                max_m: g.body_box_max_m,
            };
            (
                self.target_bounding_radius_m.unwrap_or(g.bounding_radius_m),
                Some(self.body_box.unwrap_or(package_box)),
            )
        } else {
            (
                self.target_bounding_radius_m.unwrap_or_default(),
                self.body_box,
            )
        };
        let config = self.with_region(radius_m, body_box);
        config.validate()?;
        Ok(config)
    }
}

impl ServiceConfig for IngestServiceConfig {
    /// Checks every key without loading the target (the region keys it
    /// leaves unset are checked when the package gives them).
    fn validate(&self) -> Result<(), String> {
        if self.target.is_empty() {
            return Err("target must not be empty".into());
        }
        if !(self.target_scale.is_finite() && self.target_scale > 0.0) {
            return Err(format!("target_scale = {} must be > 0", self.target_scale));
        }
        let radius = self.target_bounding_radius_m.unwrap_or(1.0);
        self.with_region(radius, self.body_box)
            .validate()
            .map_err(|e| e.to_string())
    }
}
