//! Refinement of the CNN estimate (seed 004 §III.E): the smoothed NDT of
//! seed 000 §3.1 from the network's pose, on the cloud voxel-filtered at
//! 2 cm (§V.B), then the f_CONV failure check of seed 002 §4.5.
//!
//! f_CONV is the figure of the acquisition crate (`spacepose-acquisition`,
//! `refine`): `Registration::f_conv_m2` of a point-to-point ICP
//! (`register_icp`, `IcpParams::default()`, the final stage of template
//! matching) run to convergence, here from the NDT pose: the mean squared
//! distance of every point to the nearest model point, without any
//! distance cut. The pose is accepted when `f_CONV <= f_MAX`.

use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use spacepose_geometry::voxel::VoxelFilter;
use spacepose_geometry::{Point, Pose};
use spacepose_model::{RangeMargin, RayConsistency, Target, ray_consistency};
use spacepose_registration::{
    IcpModel, IcpParams, NdtMap, NdtMapParams, NdtParams, RegistrationError, ScanTimes,
    register_ct_ndt, register_icp, register_ndt,
};

use crate::error::CnnError;

/// How the CNN estimate is refined and checked.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RefinementConfig {
    /// Voxel filter before NDT (m): 2 cm in seed 004 §V.B.
    pub voxel_m: f64,
    /// At most this many voxel points enter NDT and the f_CONV ICP (every
    /// k-th in scan order; 0 = all). Not in the paper: near the sensor a
    /// Mid-40 frame keeps 10-20k points after the 2 cm filter, and the
    /// run time grows with them while the accuracy does not.
    pub max_points: usize,
    /// Wider NDT stages (maximum point-to-cell distance, m) run before the
    /// final one, to widen the basin around the network's estimate (not in
    /// the paper, whose single stage uses 7.5 cm).
    pub ndt_stages_m: Vec<f64>,
    /// Iteration limit of each wider stage.
    pub ndt_stage_iterations: usize,
    /// At most this many points in the wider stages (every k-th; 0 = as
    /// many as the final stage): they only bring the pose into the final
    /// stage's basin, and their lookups beyond the map's 7.5 cm grid go
    /// through the kd-tree.
    pub ndt_stage_points: usize,
    /// The final NDT stage: 7.5 cm, 1 mm / 0.05°, 30 iterations (§V.B).
    pub ndt: NdtParams,
    /// Motion-blur correction (not in seed 004): a rigid fit of a blurred
    /// cloud is the pose near the points' mean time, not at the end of the
    /// scan. With this on, the continuous-time NDT of seed 000 §3.3 (Eq.
    /// 13-14) then estimates the pose at the last point's time, the start
    /// pose being the rigid fit held at the mean time (earlier points
    /// extrapolate the constant-velocity motion). Scans shorter than
    /// `deblur_min_span_s` skip it.
    pub deblur: bool,
    /// Shortest scan (last point time − mean point time, s) worth deblurring.
    pub deblur_min_span_s: f64,
    /// The NDT map (cell size 7.5 cm, §V.B).
    pub map: NdtMapParams,
    /// Spacing of the model cloud sampled on the target mesh (m).
    pub model_spacing_m: f64,
    /// Seed of that sampling.
    pub model_seed: u64,
    /// Optional NDT map file: loaded when present (its parameters must match
    /// `map`), else built and saved there.
    pub map_file: Option<PathBuf>,
    /// The ICP whose cost at convergence is f_CONV (seed 002 §4.5): the
    /// acquisition crate's final stage (10 cm), stopped at 0.1 mm / 0.1 mrad
    /// or 10 iterations, as it starts from the converged NDT pose.
    pub icp: IcpParams,
    /// f_MAX (m²): the estimate is accepted when `f_CONV <= f_MAX`.
    pub f_max_m2: f64,
    /// Range margin of the ray-consistency check at zero range (m): a
    /// point within the margin of the model's first surface on its ray is
    /// explained (`spacepose_model::consistency`).
    pub consistency_margin_m: f64,
    /// Growth of that margin per metre of range (m/m): the Mid-40's beam
    /// footprint (0.28° half-angle ≈ 0.005 m/m). With a constant 5 cm the
    /// true poses at 15-20 m explained only 74 % of their points (median;
    /// 16 % at worst), and the twin check flipped two of them.
    pub consistency_margin_per_m: f64,
}

impl Default for RefinementConfig {
    fn default() -> Self {
        Self {
            voxel_m: 0.02,
            max_points: 3000,
            // The paper's single 7.5 cm stage: with the trained deos model,
            // wider stages [0.3, 0.15] m lowered the refined success on
            // `spacepose eval cnn --seed 1001` (89.2 % against 90.4 %
            // without deblurring): they let the fit slide along the body.
            ndt_stages_m: Vec::new(),
            ndt_stage_iterations: 10,
            ndt_stage_points: 1000,
            ndt: NdtParams {
                max_iterations: 30,
                ..NdtParams::default()
            },
            deblur: true,
            deblur_min_span_s: 0.05,
            map: NdtMapParams::default(),
            model_spacing_m: 0.015,
            model_seed: 0,
            map_file: None,
            icp: IcpParams {
                max_iterations: 10,
                termination_increment: 1e-4,
                ..IcpParams::default()
            },
            f_max_m2: DEFAULT_F_MAX_M2,
            consistency_margin_m: 0.05,
            consistency_margin_per_m: 0.005,
        }
    }
}

/// Default f_MAX (m²), the template matcher's. On `spacepose eval cnn
/// --seed 1001` (1000 held-out deos frames) every refined success stays
/// below it (max 1.5e-2, median 7.5e-4 m²), but the CNN's failures (near-
/// symmetric flips, mostly at 2.5-5 m) fit as well (min 3.4e-4, median
/// 8.0e-4 m²): f_CONV only rejects refinements that did not fit at all.
pub const DEFAULT_F_MAX_M2: f64 = 0.02;

impl RefinementConfig {
    /// Rejects NaN, infinite and non-positive values.
    ///
    /// # Errors
    /// [`CnnError::InvalidParameter`] or [`CnnError::Registration`].
    pub fn validate(&self) -> Result<(), CnnError> {
        let positive = |name: &'static str, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(CnnError::InvalidParameter { name, value })
            }
        };
        positive("voxel_m", self.voxel_m)?;
        positive("model_spacing_m", self.model_spacing_m)?;
        positive("f_max_m2", self.f_max_m2)?;
        positive("consistency_margin_m", self.consistency_margin_m)?;
        if !(self.consistency_margin_per_m.is_finite() && self.consistency_margin_per_m >= 0.0) {
            return Err(CnnError::InvalidParameter {
                name: "consistency_margin_per_m",
                value: self.consistency_margin_per_m,
            });
        }
        for &d in &self.ndt_stages_m {
            positive("ndt_stages_m", d)?;
        }
        if self.ndt_stage_iterations == 0 {
            return Err(CnnError::InvalidParameter {
                name: "ndt_stage_iterations",
                value: 0.0,
            });
        }
        self.ndt.validate()?;
        self.map.validate()?;
        self.icp.validate()?;
        Ok(())
    }
}

/// The refined pose and the figures of the failure check.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Refined {
    /// NDT pose (target body → sensor), at the last point's time when
    /// deblurred.
    pub t_sensor_target: Pose,
    /// The rigid NDT pose (before deblurring).
    pub t_sensor_target_rigid: Pose,
    /// The refined points (voxel-filtered, decimated; sensor frame).
    #[serde(skip)]
    pub sensed: Vec<Vector3<f64>>,
    /// f_CONV (m²); infinite when the ICP failed.
    pub f_conv_m2: f64,
    /// The pose was moved to the last point's time by the CT-NDT.
    pub deblurred: bool,
    /// Gauss-Newton iterations over every NDT stage.
    pub ndt_iterations: usize,
    /// The final NDT stage converged.
    pub ndt_converged: bool,
    /// Inlier fraction of the final NDT stage.
    pub ndt_inlier_fraction: f64,
    /// Points after the voxel filter.
    pub points: usize,
    /// Time of the voxel filter and NDT (ms).
    pub ndt_ms: f64,
    /// Time of the f_CONV ICP (ms).
    pub fconv_ms: f64,
}

/// The NDT map and ICP model of one target, built (or loaded) once.
#[derive(Debug)]
pub struct Refiner {
    config: RefinementConfig,
    target: Target,
    map: NdtMap,
    icp_model: IcpModel,
    voxel: std::sync::Mutex<VoxelFilter>,
}

impl Refiner {
    /// Samples the target's surface, builds the ICP model and builds or
    /// loads the NDT map.
    ///
    /// # Errors
    /// Invalid configuration, a map file built with other parameters, or a
    /// model the registration crate refuses.
    pub fn new(target: &Target, config: RefinementConfig) -> Result<Self, CnnError> {
        config.validate()?;
        let model = target.sample_surface(config.model_spacing_m, config.model_seed);
        let icp_model = IcpModel::new(&model)?;
        let map = match &config.map_file {
            Some(path) if path.exists() => load_map(path, &config.map)?,
            Some(path) => {
                let map = NdtMap::build(&model, &config.map)?;
                map.save(path)?;
                map
            }
            None => NdtMap::build(&model, &config.map)?,
        };
        let voxel = std::sync::Mutex::new(VoxelFilter::new(config.voxel_m)?);
        Ok(Self {
            config,
            target: target.clone(),
            map,
            icp_model,
            voxel,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &RefinementConfig {
        &self.config
    }

    /// Sets f_MAX (m²).
    pub fn set_f_max_m2(&mut self, f_max_m2: f64) {
        self.config.f_max_m2 = f_max_m2;
    }

    /// Refines `t_sensor_target` on `cloud` (finite points, sensor frame).
    ///
    /// # Errors
    /// A registration error (no correspondence, degenerate system): the
    /// estimate cannot be refined and must not be used.
    pub fn refine(&self, cloud: &[Point], t_sensor_target: &Pose) -> Result<Refined, CnnError> {
        let start = std::time::Instant::now();
        let points = {
            let mut voxel = self
                .voxel
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            decimate(voxel.filter(cloud)?.points, self.config.max_points)
        };
        let c = &self.config;
        let mut t_target_sensor = t_sensor_target.inverse();
        let mut iterations = 0;
        let coarse = if c.ndt_stages_m.is_empty() {
            Vec::new()
        } else {
            decimate(points.clone(), c.ndt_stage_points)
        };
        for &d in &c.ndt_stages_m {
            let params = NdtParams {
                max_distance_m: d,
                max_iterations: c.ndt_stage_iterations,
                ..c.ndt
            };
            let r = register_ndt(&self.map, &coarse, &t_target_sensor, &params)?;
            iterations += r.iterations;
            t_target_sensor = r.t_target_sensor;
        }
        let ndt = register_ndt(&self.map, &points, &t_target_sensor, &c.ndt)?;
        let t_target_sensor_end = if c.deblur {
            self.deblur(&points, &ndt.t_target_sensor)
        } else {
            None
        };
        let ndt_ms = ms(start);
        let start = std::time::Instant::now();
        let f_conv_m2 = f_conv(&self.icp_model, &points, &ndt.t_target_sensor, &c.icp);
        let sensed: Vec<Vector3<f64>> = points.iter().map(Point::position).collect();
        Ok(Refined {
            t_sensor_target: t_target_sensor_end.unwrap_or(ndt.t_target_sensor).inverse(),
            t_sensor_target_rigid: ndt.t_target_sensor.inverse(),
            deblurred: t_target_sensor_end.is_some(),
            f_conv_m2,
            ndt_iterations: iterations + ndt.iterations,
            ndt_converged: ndt.converged,
            ndt_inlier_fraction: ndt.inlier_fraction(),
            points: points.len(),
            sensed,
            ndt_ms,
            fconv_ms: ms(start),
        })
    }

    /// CT-NDT from the rigid fit `rigid` (held at the points' mean time) to
    /// the last point's time; `None` for a short scan or a failed fit.
    fn deblur(&self, points: &[Point], rigid: &Pose) -> Option<Pose> {
        let n = points.len() as f64;
        let mean_s = points.iter().map(|p| p.t).sum::<f64>() / n;
        let end_s = points.iter().map(|p| p.t).fold(f64::NEG_INFINITY, f64::max);
        let span = end_s - mean_s;
        if span.is_nan() || span < self.config.deblur_min_span_s {
            return None;
        }
        let scan = ScanTimes {
            start_s: mean_s,
            end_s,
        };
        register_ct_ndt(&self.map, points, &scan, rigid, rigid, &self.config.ndt)
            .ok()
            .map(|r| r.t_target_sensor)
    }

    /// Ray consistency of `sensed` (sensor frame) with the model at
    /// `t_sensor_target`.
    pub fn consistency(&self, sensed: &[Vector3<f64>], t_sensor_target: &Pose) -> RayConsistency {
        ray_consistency(
            &self.target,
            t_sensor_target,
            sensed,
            RangeMargin {
                base_m: self.config.consistency_margin_m,
                per_m: self.config.consistency_margin_per_m,
            },
        )
    }

    /// The target's near-symmetric twins.
    pub fn twins(&self) -> &[nalgebra::Rotation3<f64>] {
        self.target.twins()
    }

    /// The failure check of seed 002 §4.5.
    pub fn accepts(&self, f_conv_m2: f64) -> bool {
        f_conv_m2 <= self.config.f_max_m2
    }
}

/// Every k-th point so that at most `max` remain (`max == 0`: all).
fn decimate(points: Vec<Point>, max: usize) -> Vec<Point> {
    if max == 0 || points.len() <= max {
        return points;
    }
    let k = points.len().div_ceil(max);
    points.into_iter().step_by(k).collect()
}

/// f_CONV of an ICP run to convergence from `t_target_sensor`; infinite
/// when the ICP fails (no pair within its distance, degenerate pairs).
fn f_conv(model: &IcpModel, points: &[Point], t_target_sensor: &Pose, icp: &IcpParams) -> f64 {
    register_icp(model, points, t_target_sensor, icp)
        .ok()
        .and_then(|r| r.f_conv_m2)
        .unwrap_or(f64::INFINITY)
}

fn load_map(path: &Path, params: &NdtMapParams) -> Result<NdtMap, CnnError> {
    let map = NdtMap::load(path)?;
    if map.params() != params {
        return Err(CnnError::Registration(
            RegistrationError::InvalidParameter {
                name: "map_file",
                reason: format!(
                    "{} was built with other map parameters (delete it to rebuild)",
                    path.display()
                ),
            },
        ));
    }
    Ok(map)
}

/// Milliseconds since `start`.
pub(crate) fn ms(start: std::time::Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}
