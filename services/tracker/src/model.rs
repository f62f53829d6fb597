//! The target model as the tracker uses it: the smoothed NDT map and the
//! ICP kd-tree, both built once per target (seed 000 §3.1).

use crate::error::TrackError;
use nalgebra::Vector3;
use spacepose_registration::{IcpModel, NdtMap, NdtMapParams};
use std::sync::Arc;

/// Shared, immutable model structures (cheap to clone).
#[derive(Clone)]
pub struct TrackingModel {
    /// Smoothed NDT map of the model cloud.
    pub map: Arc<NdtMap>,
    /// kd-tree over the model cloud, for ICP.
    pub icp: Arc<IcpModel>,
}

impl TrackingModel {
    /// Builds both structures from a model point cloud in the target body
    /// frame (e.g. `Target::sample_surface`).
    pub fn build(
        model_target: &[Vector3<f64>],
        map_params: &NdtMapParams,
    ) -> Result<Self, TrackError> {
        let map = NdtMap::build(model_target, map_params)?;
        let icp = IcpModel::new(model_target)?;
        Ok(Self {
            map: Arc::new(map),
            icp: Arc::new(icp),
        })
    }

    /// Wraps a map loaded from disk and builds the ICP tree.
    pub fn from_map(map: NdtMap, model_target: &[Vector3<f64>]) -> Result<Self, TrackError> {
        Ok(Self {
            map: Arc::new(map),
            icp: Arc::new(IcpModel::new(model_target)?),
        })
    }
}
