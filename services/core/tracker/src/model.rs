//! The target model as the tracker uses it: the smoothed NDT map and the
//! ICP model (kd-tree + nearest-point grid), both from the model cloud
//! (seed 000 §3.1).
//!
//! The ICP model is built on first use: it is the costliest part of a start
//! (~1.2 s of grid building for deos, 90 % of a tracker's start-up with a
//! cached NDT map) and only the `icp` mode needs it. A tracker started in
//! `icp` mode builds it at start ([`crate::Tracker::new`]); one switched to
//! `icp` by a mode command builds it then, before its next frame.

use crate::error::TrackError;
use crate::visibility::VisibilityModel;
use nalgebra::Vector3;
use spacepose_registration::{IcpModel, NdtMap, NdtMapParams};
use std::sync::{Arc, OnceLock};

/// The ICP model, built from the model cloud on first use.
struct LazyIcp {
    model_target: Vec<Vector3<f64>>,
    built: OnceLock<Result<IcpModel, String>>,
}

/// Shared, immutable model structures (cheap to clone).
#[derive(Clone)]
pub struct TrackingModel {
    /// Smoothed NDT map of the model cloud.
    pub map: Arc<NdtMap>,
    /// The target's calibrated loss thresholds (from its package); they
    /// fill the `loss` keys a configuration leaves unset.
    pub thresholds: TargetThresholds,
    /// The model cloud thinned to one point per NDT cell, for the
    /// visibility gate (`crate::visibility`).
    pub visibility: Arc<VisibilityModel>,
    icp: Arc<LazyIcp>,
}

/// The cell size of seed 000 Table 1 (m): the length unit the configured
/// lengths are given for ([`crate::length_unit`]).
pub const REFERENCE_LENGTH_M: f64 = 0.075;

/// The loss thresholds that depend on the target's shape, calibrated per
/// target from simulated frames when its package is prepared (crate
/// `spacepose-prepare`; `docs/design/target-packages.md`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TargetThresholds {
    /// Largest mean NDT cost per inlier (`loss.max_mean_cost_ndt`).
    pub max_mean_cost_ndt: f64,
    /// Smallest inlier fraction (`loss.min_inlier_fraction`).
    pub min_inlier_fraction: f64,
    /// The target's length unit over the reference cell, ℓ / 7.5 cm
    /// ([`crate::length_unit`]): the factor of the map's and the tracking
    /// loop's lengths.
    pub length_scale: f64,
}

impl TargetThresholds {
    /// For a model built from a bare cloud, with no package: the values set
    /// by hand on `deos` before packages existed (10 and 0.3). A service
    /// always loads a package, so only tests and library users with their
    /// own clouds see these.
    pub const UNCALIBRATED: TargetThresholds = TargetThresholds {
        max_mean_cost_ndt: 10.0,
        min_inlier_fraction: 0.3,
        length_scale: 1.0,
    };
}

impl From<&spacepose_model::package::Calibration> for TargetThresholds {
    fn from(c: &spacepose_model::package::Calibration) -> Self {
        TargetThresholds {
            max_mean_cost_ndt: c.max_mean_cost_ndt,
            min_inlier_fraction: c.min_inlier_fraction,
            length_scale: c.length_unit_m / REFERENCE_LENGTH_M,
        }
    }
}

impl TrackingModel {
    /// Builds the NDT map from a model point cloud in the target body frame
    /// (e.g. `Target::sample_surface`); the ICP model follows on first use.
    pub fn build(
        model_target: &[Vector3<f64>],
        map_params: &NdtMapParams,
    ) -> Result<Self, TrackError> {
        let map = NdtMap::build(model_target, map_params)?;
        Ok(Self::from_map(map, model_target))
    }

    /// Wraps a map loaded from disk; the ICP model follows on first use.
    pub fn from_map(map: NdtMap, model_target: &[Vector3<f64>]) -> Self {
        let spacing = map.params().min_cell_size_m / 3.0;
        Self {
            visibility: Arc::new(VisibilityModel::new(model_target, spacing)),
            map: Arc::new(map),
            thresholds: TargetThresholds::UNCALIBRATED,
            icp: Arc::new(LazyIcp {
                model_target: model_target.to_vec(),
                built: OnceLock::new(),
            }),
        }
    }

    /// This model with a target's calibrated thresholds.
    pub fn with_thresholds(mut self, thresholds: TargetThresholds) -> Self {
        self.thresholds = thresholds;
        self
    }

    /// The ICP model, built now if it was not yet (shared by every clone).
    pub fn icp(&self) -> Result<&IcpModel, TrackError> {
        self.icp
            .built
            .get_or_init(|| IcpModel::new(&self.icp.model_target).map_err(|e| e.to_string()))
            .as_ref()
            .map_err(|e| TrackError::Model(format!("ICP model: {e}")))
    }

    /// True once the ICP model has been built.
    pub fn icp_built(&self) -> bool {
        self.icp.built.get().is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(n: usize) -> Vec<Vector3<f64>> {
        let mut pts = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (u, v) = (i as f64 / n as f64 - 0.5, j as f64 / n as f64 - 0.5);
                pts.extend([
                    Vector3::new(u, v, 0.5),
                    Vector3::new(u, v, -0.5),
                    Vector3::new(u, 0.5, v),
                    Vector3::new(0.5, u, v),
                ]);
            }
        }
        pts
    }

    #[test]
    fn the_icp_model_is_built_on_first_use_once() {
        let model = TrackingModel::build(&cube(20), &NdtMapParams::default()).unwrap();
        let clone = model.clone();
        assert!(!model.icp_built());
        let first: *const IcpModel = model.icp().unwrap();
        assert!(clone.icp_built(), "clones share the built model");
        assert!(std::ptr::eq(first, clone.icp().unwrap()));
    }

    #[test]
    fn a_bad_model_cloud_fails_on_use_not_silently() {
        let map = NdtMap::build(&cube(20), &NdtMapParams::default()).unwrap();
        let model = TrackingModel::from_map(map, &[Vector3::zeros()]);
        let e = model.icp().err().unwrap();
        assert!(e.to_string().contains("ICP model"), "{e}");
    }
}
