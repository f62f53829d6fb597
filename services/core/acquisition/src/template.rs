//! Templates (seed 002 §2.1, Fig. 2): noise-free point clouds ray-cast from
//! the target model at a candidate pose with the sensor's scan pattern.
//!
//! This is the simulator's geometric core with every effect off, not a
//! second renderer: the ray directions come from `spacepose-lidar-sim`'s
//! [`Scan`], each ray is cast with [`Target::cast_ray`] in the body frame
//! after the simulator's bounding-sphere rejection, and a hit gives the
//! point `d · distance`. A test checks it against
//! [`spacepose_lidar_sim::LidarSimulator`] with [`spacepose_lidar_sim::Effects::none`].
//! What it saves per template is the simulator's per-frame set-up (material
//! draws, scan construction, per-ray RNG and intensity work).

use nalgebra::{Rotation3, Vector3};
use spacepose_lidar_sim::{Scan, SensorConfig};
use spacepose_model::Target;
use std::sync::Arc;

/// The sensor-frame ray directions of one frame of `sensor`'s pattern,
/// thinned by `stride`: every `stride`-th row and column of a raster, every
/// `stride²`-th ray of a rosette (prism phases 0). `stride = 1` keeps every
/// ray.
pub fn template_directions(sensor: &SensorConfig, stride: usize) -> Vec<Vector3<f64>> {
    let stride = stride.max(1);
    let scan = Scan::new(
        sensor.pattern.clone(),
        0.0,
        sensor.integration_time_s,
        sensor.points_per_second,
        [0.0, 0.0],
        0.0,
    );
    match sensor.pattern.raster_grid() {
        Some((nx, _)) => (0..scan.len())
            .filter(|i| (i / nx) % stride == 0 && (i % nx) % stride == 0)
            .map(|i| scan.direction(i))
            .collect(),
        None => (0..scan.len())
            .step_by(stride * stride)
            .map(|i| scan.direction(i))
            .collect(),
    }
}

/// Renders templates of one target for a fixed set of ray directions.
#[derive(Debug, Clone)]
pub struct TemplateRenderer {
    target: Arc<Target>,
    directions: Vec<Vector3<f64>>,
    max_range_m: f64,
    bounding_radius_m: f64,
    /// The pattern is a raster (see [`TemplateRenderer::ray_spacing_rad`]).
    raster: bool,
}

impl TemplateRenderer {
    /// A renderer for `target` seen through `sensor`'s pattern thinned by
    /// `stride` (see [`template_directions`]).
    pub fn new(target: Arc<Target>, sensor: &SensorConfig, stride: usize) -> Self {
        let bounding_radius_m = target.bounding_radius();
        Self {
            target,
            directions: template_directions(sensor, stride),
            max_range_m: sensor.max_range_m,
            bounding_radius_m,
            raster: sensor.pattern.raster_grid().is_some(),
        }
    }

    /// Number of rays per template.
    pub fn rays(&self) -> usize {
        self.directions.len()
    }

    /// The angular sampling of the templates (rad), 0 with fewer than two
    /// rays:
    /// - a raster: the median angle between a ray and its
    ///   nearest neighbour (1° for seed 002's raster);
    /// - any other pattern: `√(Ω / rays)`, the spacing of a uniform grid
    ///   with as many rays over the solid angle Ω of the cone about the
    ///   boresight that holds them all. A rosette's nearest neighbour lies
    ///   along its own track, tens of times closer than the next petal, and
    ///   the sensor's frame is cast at other prism phases than the
    ///   template, so that distance says nothing of where the sensor
    ///   sampled (the reverse check with it found 40-97 % of a correct
    ///   pose's template unexplained on Mid-40 frames).
    pub fn ray_spacing_rad(&self) -> f64 {
        if self.directions.len() < 2 {
            return 0.0;
        }
        if !self.raster {
            let cos_max = self
                .directions
                .iter()
                .map(|d| d.z / d.norm())
                .fold(1.0_f64, f64::min);
            let solid_angle = 2.0 * std::f64::consts::PI * (1.0 - cos_max);
            return (solid_angle / self.directions.len() as f64).sqrt();
        }
        self.nearest_neighbour_spacing_rad()
    }

    /// Median angle (rad) between a ray and its nearest neighbour.
    fn nearest_neighbour_spacing_rad(&self) -> f64 {
        let entries: Vec<[f64; 3]> = self.directions.iter().map(|d| [d.x, d.y, d.z]).collect();
        let Ok(tree) = kiddo::ImmutableKdTree::<f64, 3>::new_from_slice(&entries) else {
            return 0.0;
        };
        let mut nearest: Vec<f64> = entries
            .iter()
            .filter_map(|q| {
                tree.query(q)
                    .nearest_n::<kiddo::SquaredEuclidean<f64>>(std::num::NonZero::new(2)?)
                    .execute()
                    .get(1)
                    .map(|n| n.distance.sqrt())
            })
            .collect();
        if nearest.is_empty() {
            return 0.0;
        }
        nearest.sort_by(f64::total_cmp);
        // Chord to angle: 2 asin(c / 2).
        2.0 * (nearest[nearest.len() / 2] / 2.0).min(1.0).asin()
    }

    /// The noise-free cloud (sensor frame) of the target at
    /// `(r_sensor_target, t_sensor_target)`, written into `out` (cleared first).
    pub fn render_into(
        &self,
        r_sensor_target: &Rotation3<f64>,
        t_sensor_target: &Vector3<f64>,
        out: &mut Vec<Vector3<f64>>,
    ) {
        out.clear();
        let r = self.bounding_radius_m;
        let reach2 = (r + 1e-6) * (r + 1e-6);
        let p2 = t_sensor_target.norm_squared();
        // Ray origin (the sensor) in the body frame.
        let origin_b = r_sensor_target.inverse_transform_vector(&(-t_sensor_target));
        for d in &self.directions {
            // The simulator's cheap rejection (bounding sphere, no divergence).
            let along = t_sensor_target.dot(d);
            if along < -r || (p2 - along * along).max(0.0) > reach2 {
                continue;
            }
            let dir_b = r_sensor_target.inverse_transform_vector(d);
            if let Some(hit) = self.target.cast_ray(&origin_b, &dir_b, self.max_range_m) {
                out.push(d * hit.distance);
            }
        }
    }

    /// [`TemplateRenderer::render_into`] into a new vector.
    pub fn render(
        &self,
        r_sensor_target: &Rotation3<f64>,
        t_sensor_target: &Vector3<f64>,
    ) -> Vec<Vector3<f64>> {
        let mut out = Vec::with_capacity(self.directions.len());
        self.render_into(r_sensor_target, t_sensor_target, &mut out);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spacepose_geometry::{Euler321, Pose};
    use spacepose_lidar_sim::{Effects, LidarSimulator};
    use spacepose_scenario::TruthState;

    #[test]
    fn template_equals_the_simulator_without_effects() {
        let target = Arc::new(Target::builtin("envisat").unwrap());
        let mut sensor = SensorConfig::raster_seed002();
        sensor.effects = Effects::none();
        let sim = LidarSimulator::new(target.clone(), sensor.clone()).unwrap();
        let renderer = TemplateRenderer::new(target, &sensor, 1);
        assert_eq!(renderer.rays(), 41 * 41);
        for (k, e) in [(20.0, 30.0, -40.0), (-120.0, 60.0, 150.0)]
            .iter()
            .enumerate()
        {
            let r = Euler321::from_degrees(e.0, e.1, e.2).to_rotation();
            let t = Vector3::new(0.4, -0.3, 30.0);
            let truth = TruthState {
                t: 1.0,
                t_sensor_target: Pose::new(r, t),
                v_sensor_target: Vector3::zeros(),
                w_target: Vector3::zeros(),
            };
            let frame = sim.simulate(&truth, &mut LidarSimulator::frame_rng(3, k as u64));
            let template = renderer.render(&r, &t);
            assert!(template.len() > 100, "{}", template.len());
            assert_eq!(frame.points.len(), template.len());
            for (p, q) in frame.points.iter().zip(&template) {
                assert!((p.position() - q).norm() < 1e-4);
            }
        }
    }

    /// Seed 002's raster is sampled every 1°; the Mid-40's 38.4° circle
    /// with N rays every √(Ω/N), which grows with the thinning.
    #[test]
    fn ray_spacing_of_a_raster_and_a_rosette() {
        let target = Arc::new(Target::builtin("deos").unwrap());
        let raster = TemplateRenderer::new(target.clone(), &SensorConfig::raster_seed002(), 1);
        let raster = raster.ray_spacing_rad().to_degrees();
        assert!((raster - 1.0).abs() < 0.07, "{raster}");
        let mid40 = SensorConfig::livox_mid40();
        let all = TemplateRenderer::new(target.clone(), &mid40, 1);
        let cone = 2.0 * std::f64::consts::PI * (1.0 - 19.2_f64.to_radians().cos());
        let expected = (cone / all.rays() as f64).sqrt();
        let got = all.ray_spacing_rad();
        assert!((got / expected - 1.0).abs() < 0.02, "{got} vs {expected}");
        let thinned = TemplateRenderer::new(target, &mid40, 4).ray_spacing_rad();
        assert!((thinned / got - 4.0).abs() < 0.1, "{thinned} vs {got}");
    }

    #[test]
    fn stride_thins_a_raster_in_both_axes() {
        let sensor = SensorConfig::raster_seed002();
        assert_eq!(template_directions(&sensor, 2).len(), 21 * 21);
        assert_eq!(template_directions(&sensor, 3).len(), 14 * 14);
        let rosette = SensorConfig::livox_mid40();
        let all = template_directions(&rosette, 1).len();
        assert_eq!(template_directions(&rosette, 4).len(), all.div_ceil(16));
    }
}
