//! The lidar simulator: one frame = one scan of the pattern over the
//! integration window, each ray traced against the moving target (and the
//! facility background), then detection, outliers and noise.

use crate::config::{SensorConfig, SurfaceModel};
use crate::detection::DetectionModel;
use crate::error::SimError;
use crate::measurement::Measurement;
use crate::mismatch::ScanPath;
use crate::pattern::Scan;
use crate::scene::{ConstantMotion, FrameScene, TargetMotion};
use crate::surface::{Surface, draw_surfaces, validate_materials};
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use spacepose_geometry::Point;
use spacepose_model::Target;
use spacepose_scenario::TruthState;
use std::sync::Arc;

// The frame types live in `frame`; their `simulator::` paths stay valid.
pub use crate::frame::{Frame, INTENSITY_REFERENCE_M2, ReturnKind};

/// High-fidelity lidar simulator for one target and one sensor.
#[derive(Debug, Clone)]
pub struct LidarSimulator {
    target: Arc<Target>,
    config: SensorConfig,
    detection: DetectionModel,
}

impl LidarSimulator {
    /// A simulator after validating the configuration and the target's materials.
    pub fn new(target: Arc<Target>, config: SensorConfig) -> Result<Self, SimError> {
        config.validate()?;
        validate_materials(target.name(), target.materials())?;
        let n = target.materials().len();
        if let Some(&bad) = target
            .mesh()
            .face_materials()
            .iter()
            .find(|&&m| usize::from(m) >= n)
        {
            return Err(SimError::BadMaterial {
                target: target.name().to_owned(),
                materials: n,
                reason: if bad == u16::MAX {
                    "face material u16::MAX"
                } else {
                    "a face refers to an undefined material"
                },
            });
        }
        let detection = config.detection.model();
        Ok(LidarSimulator {
            target,
            config,
            detection,
        })
    }

    /// The sensor configuration.
    pub fn config(&self) -> &SensorConfig {
        &self.config
    }

    /// The simulated target.
    pub fn target(&self) -> &Arc<Target> {
        &self.target
    }

    /// The surfaces of one frame, indexed by material. The Phong draws are
    /// made under both models so that the rest of the frame's random stream
    /// (noise, outliers, detection) does not depend on the surface model.
    fn frame_surfaces(&self, rng: &mut ChaCha8Rng) -> Vec<Surface> {
        let drawn = draw_surfaces(self.target.materials(), rng);
        match self.config.surface_model {
            SurfaceModel::Phong => drawn,
            SurfaceModel::Lambertian => drawn
                .iter()
                .map(|s| Surface::lambertian(s.reflectance))
                .collect(),
        }
    }

    /// An independent, reproducible random stream for frame `frame_index` of
    /// a run seeded with `seed` (ChaCha8, one stream per frame).
    pub fn frame_rng(seed: u64, frame_index: u64) -> ChaCha8Rng {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(frame_index);
        rng
    }

    /// Simulates one scan over `[scan_end - integration_time, scan_end]`,
    /// `scan_end = truth.t`; the target moves with the constant velocity and
    /// angular velocity of `truth` (taken at scan end) during the scan.
    ///
    /// A truth state holding NaN or infinity yields an empty frame; use
    /// [`LidarSimulator::try_simulate`] to get the error instead.
    pub fn simulate(&self, truth: &TruthState, rng: &mut ChaCha8Rng) -> Frame {
        self.try_simulate(truth, rng).unwrap_or_else(|_| Frame {
            points: Vec::new(),
            kinds: Vec::new(),
            scan_start: truth.t - self.config.integration_time_s,
            scan_end: truth.t,
            truth: *truth,
        })
    }

    /// [`LidarSimulator::simulate`], with an error for a non-finite truth state.
    pub fn try_simulate(
        &self,
        truth: &TruthState,
        rng: &mut ChaCha8Rng,
    ) -> Result<Frame, SimError> {
        let motion = TargetMotion::Constant(scan_motion(truth, self.config.effects.motion_blur));
        self.simulate_moving(truth, motion, rng)
    }

    /// One scan ending at `truth.t` with the target moving along `path`
    /// (the world's own motion: [`crate::mismatch`]) instead of the
    /// constant velocities of `truth`; `path` should cover the scan window
    /// `[truth.t - integration_time_s, truth.t]`. Motion blur off holds
    /// the target at the path's scan-end pose.
    ///
    /// # Errors
    /// A non-finite truth state.
    pub fn try_simulate_along(
        &self,
        truth: &TruthState,
        path: &ScanPath,
        rng: &mut ChaCha8Rng,
    ) -> Result<Frame, SimError> {
        let motion = match self.config.effects.motion_blur {
            true => TargetMotion::Sampled(path),
            false => TargetMotion::Constant(scan_motion(truth, false)),
        };
        self.simulate_moving(truth, motion, rng)
    }

    fn simulate_moving(
        &self,
        truth: &TruthState,
        motion: TargetMotion<'_>,
        rng: &mut ChaCha8Rng,
    ) -> Result<Frame, SimError> {
        if !truth_is_finite(truth) {
            return Err(SimError::NonFiniteTruth(truth.t));
        }
        let c = &self.config;
        // Per-frame draws: scan phase, then material properties (seed 004 §IV.B).
        let scan = c
            .pattern
            .scan(truth.t, c.integration_time_s, c.points_per_second, rng);
        let scene = self.frame_scene(truth, motion, rng);
        let (points, kinds) = self.measure_scan(&scan, &scene, rng);
        Ok(Frame {
            points,
            kinds,
            scan_start: scan.scan_start(),
            scan_end: truth.t,
            truth: *truth,
        })
    }

    /// The scene of the frame ending at `truth.t`: the target moving with
    /// `truth`'s velocities, this frame's surface draws (the only random
    /// draws here), the facility background if `Effects::clutter`, and the
    /// beam (divergence, reflections) as the effects ask.
    fn frame_scene<'a>(
        &'a self,
        truth: &TruthState,
        motion: TargetMotion<'a>,
        rng: &mut ChaCha8Rng,
    ) -> FrameScene<'a> {
        let c = &self.config;
        let fx = c.effects;
        FrameScene {
            target: &self.target,
            motion,
            surfaces: self.frame_surfaces(rng),
            clutter: if fx.clutter {
                c.facility.build(&self.target, &truth.t_sensor_target)
            } else {
                Vec::new()
            },
            clutter_surface: Surface::lambertian(c.facility.reflectance),
            bounding_radius: self.target.bounding_radius(),
            beta: if fx.beam_divergence {
                c.beam_divergence_deg.to_radians()
            } else {
                0.0
            },
            rays_per_beam: if fx.beam_divergence {
                c.divergent_rays
            } else {
                1
            },
            reflections: fx.reflections,
            max_range: c.max_range_m,
            echo_separation_m: c.echo_separation_m,
            reflection_offset_m: 1e-4 * self.target.bounding_radius() + 1e-6,
        }
    }

    /// Every ray of `scan` traced through `scene` and measured, in scan
    /// order: the detected points and what produced each.
    fn measure_scan(
        &self,
        scan: &Scan,
        scene: &FrameScene<'_>,
        rng: &mut ChaCha8Rng,
    ) -> (Vec<Point>, Vec<ReturnKind>) {
        let measurement = Measurement::new(&self.config, &self.detection);
        let mut points = Vec::with_capacity(scan.len() / 2);
        let mut kinds = Vec::with_capacity(scan.len() / 2);
        for (t, dir) in scan.rays() {
            let Some(echo) = scene.trace_beam(t, &dir, rng) else {
                continue;
            };
            if let Some((point, kind)) = measurement.measure(t, &dir, &echo, rng) {
                points.push(point);
                kinds.push(kind);
            }
        }
        (points, kinds)
    }
}

/// The target's motion during the scan ending at `truth.t`: `truth`'s pose
/// extrapolated backwards with its constant velocity (seed 000 Eq. 8) and
/// angular velocity (Eq. 9) when `blur`, else held at the scan-end pose.
fn scan_motion(truth: &TruthState, blur: bool) -> ConstantMotion {
    ConstantMotion {
        r_sensor_target: truth.t_sensor_target.rotation,
        t_sensor_target: truth.t_sensor_target.translation,
        v_sensor: truth.v_sensor_target,
        w_target: truth.w_target,
        t_end: truth.t,
        blur,
    }
}

/// Whether every field of `truth` (time, pose, velocities) is finite.
fn truth_is_finite(truth: &TruthState) -> bool {
    let finite = |v: &Vector3<f64>| v.iter().all(|x| x.is_finite());
    truth.t.is_finite()
        && finite(&truth.t_sensor_target.translation)
        && truth
            .t_sensor_target
            .rotation
            .matrix()
            .iter()
            .all(|x| x.is_finite())
        && finite(&truth.v_sensor_target)
        && finite(&truth.w_target)
}
