//! Density levels: a dense frame is thinned to the point budget
//! ([`crate::TemplateMatchingConfig::max_sensed_points`]) and its templates
//! are cast with the sensor's rays thinned alike, so sensed cloud and
//! templates keep the same sampling (seed 002 matched a raster frame
//! against templates of the same raster).
//!
//! Not in seed 002, whose 41 × 41 raster gives at most 1,681 points. The
//! suite's Livox Mid-40 casts about 10,000 rays a frame, and a large
//! target near the sensor returns most of them: template matching and ICP
//! on every point took 1.2-5.4 s per attempt (issue 24). Level `s` keeps
//! every `s`-th raster row and column of the templates and every `s²`-th
//! ray of a rosette, and every `s²`-th sensed point (in the order given),
//! so both densities drop by `s²`.

use crate::config::TemplateMatchingConfig;
use crate::template::TemplateRenderer;
use spacepose_lidar_sim::SensorConfig;
use spacepose_model::Target;
use std::sync::Arc;

/// Thinning strides available (a factor of up to 64 in density).
pub(super) const MAX_STRIDE: usize = 8;

/// The templates of one density level.
#[derive(Debug, Clone)]
pub(super) struct Density {
    /// Full-resolution templates at this level.
    pub(super) renderer: TemplateRenderer,
    /// The coarse first pass, if configured.
    pub(super) coarse: Option<TemplateRenderer>,
    /// Tolerance of the reverse check (rad): `unexplained_spacings` times
    /// the ray spacing of this level's sampling.
    pub(super) tolerance_rad: f64,
}

impl Density {
    /// Level `stride` for `target` seen through `sensor`.
    pub(super) fn new(
        target: &Arc<Target>,
        sensor: &SensorConfig,
        config: &TemplateMatchingConfig,
        stride: usize,
    ) -> Self {
        let fine = config.template_stride * stride;
        let renderer = TemplateRenderer::new(target.clone(), sensor, fine);
        // The reverse check compares with the sensor's sampling at this
        // level, whatever thinning the templates add on top of it.
        let spacing = if fine == stride {
            renderer.ray_spacing_rad()
        } else {
            TemplateRenderer::new(target.clone(), sensor, stride).ray_spacing_rad()
        };
        Self {
            renderer,
            coarse: config
                .coarse_to_fine
                .map(|c| TemplateRenderer::new(target.clone(), sensor, c.stride * fine)),
            tolerance_rad: config.unexplained_spacings * spacing,
        }
    }

    /// Every level a matcher may need: stride 1 only without a budget.
    pub(super) fn levels(
        target: &Arc<Target>,
        sensor: &SensorConfig,
        config: &TemplateMatchingConfig,
    ) -> Vec<Self> {
        let top = if config.max_sensed_points > 0 {
            MAX_STRIDE
        } else {
            1
        };
        (1..=top)
            .map(|s| Self::new(target, sensor, config, s))
            .collect()
    }
}

/// The stride (1-based index into the levels) that brings `points` within
/// `budget`: the smallest `s` with `⌈points / s²⌉ ≤ budget`, at most
/// `levels`; 1 without a budget (`budget` 0).
pub(super) fn stride_for(points: usize, budget: usize, levels: usize) -> usize {
    if budget == 0 {
        return 1;
    }
    (1..=levels.max(1))
        .find(|s| points.div_ceil(s * s) <= budget)
        .unwrap_or(levels.max(1))
}

#[cfg(test)]
mod tests {
    use super::super::TemplateMatcher;
    use super::*;
    use crate::config::Threads;
    use nalgebra::Vector3;
    use spacepose_geometry::{Euler321, Pose, so3};
    use spacepose_lidar_sim::LidarSimulator;
    use spacepose_scenario::TruthState;

    #[test]
    fn stride_is_the_smallest_within_the_budget() {
        assert_eq!(stride_for(6665, 0, 8), 1);
        assert_eq!(stride_for(1500, 1500, 8), 1);
        assert_eq!(stride_for(1501, 1500, 8), 2);
        assert_eq!(stride_for(6000, 1500, 8), 2);
        assert_eq!(stride_for(6001, 1500, 8), 3);
        assert_eq!(stride_for(1_000_000, 1500, 8), 8);
        assert_eq!(stride_for(10, 1500, 1), 1);
    }

    /// The point budget: a dense Mid-40 frame of deos at 8 m (every sensor
    /// effect on) is thinned to at most `max_sensed_points`, its templates
    /// alike, and the pose is still found; without the budget every point is
    /// used.
    #[test]
    fn a_dense_rosette_frame_is_thinned_to_the_budget() {
        let deos = Arc::new(Target::builtin("deos").unwrap());
        let sensor = SensorConfig::livox_mid40();
        let config = TemplateMatchingConfig {
            threads: Threads::Single,
            ..TemplateMatchingConfig::default()
        };
        let m = TemplateMatcher::new(deos.clone(), sensor.clone(), config.clone()).unwrap();
        assert_eq!(m.levels.len(), MAX_STRIDE);
        let r = Euler321::from_degrees(35.0, -20.0, 70.0).to_rotation();
        let truth = TruthState {
            t: 1.0,
            t_sensor_target: Pose::new(r, Vector3::new(0.3, -0.2, 8.0)),
            v_sensor_target: Vector3::zeros(),
            w_target: Vector3::zeros(),
        };
        let sim = LidarSimulator::new(deos, sensor).unwrap();
        let cloud = sim
            .simulate(&truth, &mut LidarSimulator::frame_rng(11, 0))
            .points;
        assert!(
            cloud.len() > 4 * config.max_sensed_points,
            "{}",
            cloud.len()
        );
        let out = m.acquire(&cloud).unwrap();
        assert!(
            out.points_used <= config.max_sensed_points && out.points_used > 300,
            "{}",
            out.points_used
        );
        let err_deg = so3::distance(&out.t_sensor_target.rotation, &r).to_degrees();
        assert!(err_deg < 3.0 && out.accepted, "{err_deg} deg {out:?}");
        let all = m.prepare(&cloud).unwrap();
        // 12,998 points: ⌈/9⌉ = 1,445 is over the budget, ⌈/16⌉ = 813 is not.
        assert_eq!(cloud.len(), 12_998);
        assert_eq!(all.density + 1, 4);
        assert_eq!(all.finite.len(), out.points_used);
    }
}
