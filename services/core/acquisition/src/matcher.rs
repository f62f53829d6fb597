//! The on-line template matcher of seed 002 §2 (Fig. 2) with ICP
//! refinement and the f_CONV failure check of §4.5 (Fig. 10).

use crate::config::TemplateMatchingConfig;
use crate::error::AcquisitionError;
use crate::grid::euler_grid;
use crate::visibility::SensedTree;
use density::Density;
use nalgebra::{Rotation3, Vector3};
use spacepose_geometry::{Euler321, Point, Pose};
use spacepose_lidar_sim::{LidarSimulator, SensorConfig};
use spacepose_model::Target;
use spacepose_registration::IcpModel;
use std::sync::Arc;
use std::time::Instant;

mod candidates;
mod density;
mod refinements;
mod scoring;
mod second_chance;
mod stages;
mod twins;

/// Seed of the model-cloud sampling (any fixed value: the cloud is deterministic).
const MODEL_SEED: u64 = 0x5eed_0002;

/// The template matcher for one target and one sensor: attitude grid,
/// template renderers and ICP model are built once here.
#[derive(Debug)]
pub struct TemplateMatcher {
    target: Arc<Target>,
    sensor: SensorConfig,
    config: TemplateMatchingConfig,
    grid: Vec<(Euler321, Rotation3<f64>)>,
    /// The template renderers of each density level, stride 1 first.
    levels: Vec<Density>,
    icp_model: IcpModel,
    /// The coarser model of the wide ICP stages, if configured.
    stage_model: Option<IcpModel>,
    /// Reach of the translation vote (m): the radius of the model's
    /// bounding box.
    vote_reach_m: f64,
}

impl TemplateMatcher {
    /// Validates the configuration and the sensor, builds the Euler grid,
    /// the template renderers and the ICP model (a surface sample of the
    /// mesh at `model_spacing_m` with its lookup grid, ~1 s).
    pub fn new(
        target: Arc<Target>,
        sensor: SensorConfig,
        config: TemplateMatchingConfig,
    ) -> Result<Self, AcquisitionError> {
        config.validate()?;
        // The simulator's own validation of the sensor and the materials.
        LidarSimulator::new(target.clone(), sensor.clone())?;
        let grid = euler_grid(config.delta_deg)?
            .into_iter()
            .map(|e| (e, e.to_rotation()))
            .collect();
        let levels = Density::levels(&target, &sensor, &config);
        let model = target.sample_surface(config.model_spacing_m, MODEL_SEED);
        let vote_reach_m = bounding_radius(&model);
        let with_far = |m: IcpModel| {
            let mut levels = config.far_lookup.iter().flat_map(|f| &f.levels);
            levels.try_fold(m, |m, l| m.with_far_lookup(l.margin_m, l.resolution_m))
        };
        // Both models get the far lookup: the refinement's widest stage
        // after screening runs on the full model.
        let (icp_model, stage_model) = if config.stage_model_spacing_m > 0.0 {
            let coarse = target.sample_surface(config.stage_model_spacing_m, MODEL_SEED);
            (
                with_far(IcpModel::new(&model)?)?,
                Some(with_far(IcpModel::new(&coarse)?)?),
            )
        } else {
            // The full model serves the wide stages too.
            (with_far(IcpModel::new(&model)?)?, None)
        };
        Ok(Self {
            target,
            sensor,
            config,
            grid,
            levels,
            icp_model,
            stage_model,
            vote_reach_m,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &TemplateMatchingConfig {
        &self.config
    }

    /// The sensor the templates are rendered for.
    pub fn sensor(&self) -> &SensorConfig {
        &self.sensor
    }

    /// The target.
    pub fn target(&self) -> &Arc<Target> {
        &self.target
    }

    /// The ICP model (target surface sample with its lookup structures).
    pub fn icp_model(&self) -> &IcpModel {
        &self.icp_model
    }

    /// The model of the wide ICP stages (the ICP model when
    /// `stage_model_spacing_m` is 0).
    pub fn stage_model(&self) -> &IcpModel {
        self.stage_model.as_ref().unwrap_or(&self.icp_model)
    }

    /// The grid attitudes `(Euler angles, rotation)`.
    pub fn grid(&self) -> &[(Euler321, Rotation3<f64>)] {
        &self.grid
    }

    /// Number of grid attitudes (templates per full pass).
    pub fn grid_len(&self) -> usize {
        self.grid.len()
    }

    /// Rays per full-resolution template.
    pub fn template_rays(&self) -> usize {
        self.levels[0].renderer.rays()
    }

    /// Sets f_MAX (m²), e.g. after `spacepose calibrate fconv`.
    pub fn set_f_max_m2(&mut self, f_max_m2: f64) -> Result<(), AcquisitionError> {
        let config = TemplateMatchingConfig {
            f_max_m2,
            ..self.config.clone()
        };
        config.validate()?;
        self.config = config;
        Ok(())
    }

    /// The acceptance test: f_CONV ≤ f_MAX (seed 002 §4.5) and the
    /// unexplained fraction ≤ `u_max`.
    fn acceptable(&self, f_conv_m2: f64, unexplained: f64) -> bool {
        f_conv_m2.is_finite()
            && f_conv_m2 <= self.config.f_max_m2
            && unexplained <= self.config.u_max
    }

    /// The unexplained fraction of `t_sensor_target` (see
    /// [`crate::visibility`]) with the templates of `density`.
    fn unexplained(&self, density: &Density, sensed: &SensedTree, t_sensor_target: &Pose) -> f64 {
        let mut template = Vec::new();
        density.renderer.render_into(
            &t_sensor_target.rotation,
            &t_sensor_target.translation,
            &mut template,
        );
        sensed.unexplained_fraction(&template, density.tolerance_rad)
    }
}

/// Half the diagonal of the bounding box of `points` (m).
fn bounding_radius(points: &[Vector3<f64>]) -> f64 {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    0.5 * (hi - lo).norm()
}

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

#[cfg(test)]
#[path = "matcher_tests.rs"]
mod tests;

/// An evenly strided subsample of about `max_points` of `cloud` (all of it
/// when `max_points` is 0 or the cloud is no larger).
fn strided(cloud: &[Point], max_points: usize) -> Vec<Point> {
    let stride = if max_points > 0 && cloud.len() > max_points {
        cloud.len().div_ceil(max_points)
    } else {
        1
    };
    cloud.iter().step_by(stride).copied().collect()
}
