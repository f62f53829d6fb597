//! `spacepose demo --target SPEC [--scale S]`: the main job on another
//! target, with no hand-edited descriptor.
//!
//! The target is resolved once here (a package directory, a built-in
//! name, a mesh file prepared into the cache, or `zoo:N`), so a target
//! that cannot be used fails in one line before anything starts. Every
//! service that takes a target then gets the package itself (its
//! directory, or the built-in name), so none prepares it again: the
//! simulated sensor, ingest, the trackers and init take their numbers from
//! the package. The sensor's legs are moved out so that the whole target
//! is in view at the fly-around and within ingest's range gate
//! (`range_scale_to_fit`).

use super::super::descriptor::Descriptor;
use anyhow::{Context, Result};
use spacepose_ingest::IngestConfig;
use spacepose_lidar_sim::pattern::MID40_FOV_DEG;
use spacepose_messages::ServiceKind;
use spacepose_scenario::presets::range_scale_to_fit;
use toml::Value;

/// What the services are told about the target.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetOverride {
    /// The spec every service loads: the package directory, or a built-in
    /// name at scale 1.
    pub spec: String,
    /// The package's bounding radius (m).
    pub bounding_radius_m: f64,
    /// The package's symmetry group, for scoring.
    pub symmetries: Vec<nalgebra::Rotation3<f64>>,
}

impl TargetOverride {
    /// Resolves `spec` at `scale` (preparing a mesh on first use).
    pub fn resolve(spec: &str, scale: f64) -> Result<TargetOverride> {
        let package =
            spacepose_prepare::resolve(spec, scale).with_context(|| format!("--target {spec}"))?;
        let spec = match &package.dir {
            Some(dir) => std::path::absolute(dir)
                .with_context(|| format!("{}", dir.display()))?
                .to_string_lossy()
                .into_owned(),
            None => spec.to_owned(),
        };
        Ok(TargetOverride {
            spec,
            bounding_radius_m: package.target.bounding_radius(),
            symmetries: package.target.symmetries().to_vec(),
        })
    }

    /// The sensor's range scale in `d`: the target in view and within
    /// ingest's range gate (`max_range_m`, the smallest of the
    /// descriptor's ingest services, else ingest's default).
    pub fn range_scale(&self, d: &Descriptor) -> f64 {
        let gate = d
            .instances_of(ServiceKind::Ingest)
            .filter_map(|s| s.config.get("max_range_m").and_then(Value::as_float))
            .fold(IngestConfig::default().max_range_m, f64::min);
        range_scale_to_fit(self.bounding_radius_m, MID40_FOV_DEG, gate)
    }

    /// Sets the target of every service that takes one, and the sensor's
    /// range scale; returns the range scale.
    pub fn apply(&self, d: &mut Descriptor) -> f64 {
        let range_scale = self.range_scale(d);
        let spec = Value::String(self.spec.clone());
        for s in d.instances_of_mut(ServiceKind::LidarSim) {
            s.config.insert("target".into(), spec.clone());
            s.config.insert("scale".into(), Value::Float(1.0));
            s.config
                .insert("range_scale".into(), Value::Float(range_scale));
        }
        for kind in [ServiceKind::Ingest, ServiceKind::Tracker, ServiceKind::Init] {
            for s in d.instances_of_mut(kind) {
                s.config.insert("target".into(), spec.clone());
                s.config.insert("target_scale".into(), Value::Float(1.0));
            }
        }
        range_scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_service_with_a_target_gets_the_package() {
        let mut d = Descriptor::load(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../deploy/demo.toml"
        )))
        .expect("demo.toml");
        let o = TargetOverride::resolve("envisat", 1.0).expect("envisat");
        let range_scale = o.apply(&mut d);
        // In view from 80 m, but held within ingest's 60 m gate.
        assert!((range_scale * 15.0 + o.bounding_radius_m - 60.0).abs() < 1e-9);
        let mut set = 0;
        for s in &d.services {
            if let Some(t) = s.config.get("target") {
                assert_eq!(t.as_str(), Some("envisat"), "{}", s.name);
                set += 1;
            }
        }
        assert_eq!(set, 4);
        let sensor = d
            .instances_of(ServiceKind::LidarSim)
            .next()
            .expect("sensor");
        let scale = sensor.config.get("range_scale").and_then(Value::as_float);
        assert_eq!(scale, Some(range_scale));
        let deos = TargetOverride::resolve("deos", 1.0).expect("deos");
        assert_eq!(deos.range_scale(&d), 1.0);
        assert_eq!(deos.symmetries.len(), 3, "deos's ±120° group");
        let err = TargetOverride::resolve("no/such/mesh.stl", 1.0).unwrap_err();
        assert!(format!("{err:#}").contains("no/such/mesh.stl"), "{err:#}");
    }
}
