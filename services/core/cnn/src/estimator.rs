//! The seed 004 pose estimator: preprocessing (§III.A) → network (§III.D)
//! → Γ_sym decoding (Algorithm 1) and position = ROI centre + offset
//! (§III.B) → NDT refinement (§III.E) → f_CONV check (seed 002 §4.5).
//!
//! ```no_run
//! # fn demo(cloud: &[spacepose_geometry::Point]) -> Result<(), spacepose_cnn::CnnError> {
//! use spacepose_cnn::estimator::CnnEstimator;
//! use spacepose_inference::Engine;
//! let estimator = CnnEstimator::load("services/core/cnn/models/deos".as_ref(), Engine::Tract)?;
//! let e = estimator.estimate(cloud)?;
//! if e.accepted { println!("{:?} in {:.1} ms", e.t_sensor_target, e.time_ms.total); }
//! # Ok(()) }
//! ```

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Instant;

use serde::Serialize;
use spacepose_geometry::{Point, Pose};
use spacepose_inference::{Engine, ModelShape, PoseNet};
use spacepose_model::Target;

use crate::classes::{ClassTable, DEFAULT_ROLL_STEP_DEG};
use crate::decode::{DEFAULT_DELTA_BETA_DEG, decode};
use crate::error::CnnError;
use crate::model_meta::{ModelMeta, model_onnx_path};
use crate::preprocess::{DepthImage, PreprocessConfig, preprocess};
use crate::refinement::{RefinementConfig, Refiner, ms};
use crate::twins::{TwinCheckConfig, TwinOutcome};

mod estimate;
mod hypotheses;
pub use estimate::{CnnEstimate, Timings};

/// Fewer finite points than this is an error, never an estimate.
pub const MIN_POINTS: usize = 20;
/// Default [`EstimatorConfig::hypotheses`].
pub const DEFAULT_HYPOTHESES: usize = 3;

/// Estimator settings beyond what `model.json` fixes.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EstimatorConfig {
    /// Roll step Δα of the class table (deg); the model must match it.
    pub roll_step_deg: f64,
    /// Δβ of Algorithm 1 (deg).
    pub delta_beta_deg: f64,
    /// Minimum finite points (at least [`MIN_POINTS`]).
    pub min_points: usize,
    /// Attitude hypotheses refined at most: the modes of the network's
    /// output (classes at least Δβ apart, in decreasing probability, each
    /// decoded by Algorithm 1 around it) are refined in turn until one
    /// passes the f_CONV check; none passing, the lowest f_CONV is kept.
    /// 1 = the paper (only Γ_sym's estimate). A frame the first hypothesis
    /// passes costs one refinement whatever this is.
    pub hypotheses: usize,
    /// Refinement and failure check.
    pub refinement: RefinementConfig,
    /// The twin check after the refinement ([`crate::twins`]).
    pub twins: TwinCheckConfig,
}

impl Default for EstimatorConfig {
    fn default() -> Self {
        Self {
            roll_step_deg: DEFAULT_ROLL_STEP_DEG,
            delta_beta_deg: DEFAULT_DELTA_BETA_DEG,
            min_points: MIN_POINTS,
            hypotheses: DEFAULT_HYPOTHESES,
            refinement: RefinementConfig::default(),
            twins: TwinCheckConfig::default(),
        }
    }
}

/// The network's pose of one frame (§III.B, §III.D), decoded.
struct NetworkPose {
    /// Γ_sym's attitude (Algorithm 1) at the ROI centre plus the offset.
    raw: Pose,
    /// The network's class probabilities.
    probs: Vec<f32>,
    /// Δβ of Algorithm 1 (rad).
    delta_beta: f64,
    /// Class of largest probability.
    top_class: usize,
    /// Its probability.
    top_probability: f32,
}

/// A loaded network with its class table, preprocessing and refinement
/// model. `estimate` takes `&self` (the network sits behind a mutex).
#[derive(Debug)]
pub struct CnnEstimator {
    net: Mutex<PoseNet>,
    classes: ClassTable,
    preprocess: PreprocessConfig,
    refiner: Refiner,
    config: EstimatorConfig,
    meta: ModelMeta,
    dir: PathBuf,
}

impl CnnEstimator {
    /// Loads `model_dir` (`model.onnx` + `model.json`) for the target the
    /// model names, with the default settings.
    ///
    /// # Errors
    /// See [`CnnEstimator::load_with`].
    pub fn load(model_dir: &Path, engine: Engine) -> Result<Self, CnnError> {
        let meta = ModelMeta::read(model_dir)?;
        let target = Target::resolve(&meta.target, 1.0).map_err(|e| CnnError::Target {
            name: meta.target.clone(),
            reason: e.to_string(),
        })?;
        Self::load_with(
            model_dir,
            engine,
            Arc::new(target),
            EstimatorConfig::default(),
        )
    }

    /// Loads `model_dir` for `target`: reads `model.json`, checks l, Δα, m
    /// and the class table against this crate's for `target` (N against
    /// the network's input), loads the network (checked against the ONNX
    /// contract), then builds the NDT map and ICP model (~1 s, or loads the
    /// map file).
    ///
    /// # Errors
    /// [`CnnError::ModelDir`] (missing directory or file),
    /// [`CnnError::ModelMeta`], [`CnnError::ModelMismatch`],
    /// [`CnnError::Inference`] (bad ONNX, engine unavailable), configuration
    /// and map errors.
    pub fn load_with(
        model_dir: &Path,
        engine: Engine,
        target: Arc<Target>,
        config: EstimatorConfig,
    ) -> Result<Self, CnnError> {
        if config.min_points < MIN_POINTS {
            return Err(CnnError::InvalidParameter {
                name: "min_points",
                value: config.min_points as f64,
            });
        }
        if config.hypotheses == 0 {
            return Err(CnnError::InvalidParameter {
                name: "hypotheses",
                value: 0.0,
            });
        }
        if !(config.delta_beta_deg.is_finite() && config.delta_beta_deg > 0.0) {
            return Err(CnnError::InvalidParameter {
                name: "delta_beta_deg",
                value: config.delta_beta_deg,
            });
        }
        let onnx = model_onnx_path(model_dir)?;
        let meta = ModelMeta::read(model_dir)?;
        let preprocess = PreprocessConfig::for_target(&target, meta.image_size)?;
        let classes = ClassTable::for_target(&target, config.roll_step_deg)?;
        meta.check(model_dir, target.name(), &preprocess, &classes)?;
        let shape = ModelShape {
            image_size: preprocess.image_size,
            classes: classes.len(),
        };
        let net = PoseNet::load(&onnx, engine, shape)?;
        let refiner = Refiner::new(&target, config.refinement.clone())?;
        Ok(Self {
            net: Mutex::new(net),
            classes,
            preprocess,
            refiner,
            config,
            meta,
            dir: model_dir.to_path_buf(),
        })
    }

    /// Estimates `t_sensor_target` from one cloud (sensor frame).
    ///
    /// A refinement that fails is not an error: the estimate then has
    /// `accepted == false` and `refinement_error` set.
    ///
    /// # Errors
    /// [`CnnError::TooFewPoints`] below `min_points` finite points (an
    /// all-NaN cloud included); preprocessing or network errors.
    pub fn estimate(&self, cloud: &[Point]) -> Result<CnnEstimate, CnnError> {
        let start = Instant::now();
        let finite = self.finite_points(cloud)?;
        let image = preprocess(&finite, &self.preprocess)?;
        let preprocess_ms = ms(start);

        let t = Instant::now();
        let net = self.network_pose(&image)?;
        let inference_ms = ms(t);

        let t = Instant::now();
        let (refined, twins) = self.refine_and_check_twins(&finite, &net);
        let refinement_ms = ms(t);
        let time_ms = Timings {
            preprocess: preprocess_ms,
            inference: inference_ms,
            refinement: refinement_ms,
            total: ms(start),
        };
        let mut estimate = unrefined_estimate(
            &net,
            finite.len(),
            image.points_in_roi,
            refined.tried,
            twins,
            time_ms,
        );
        self.report_refinement(&mut estimate, refined);
        Ok(estimate)
    }

    /// The finite points of `cloud`.
    ///
    /// # Errors
    /// [`CnnError::TooFewPoints`] below `min_points` of them.
    fn finite_points(&self, cloud: &[Point]) -> Result<Vec<Point>, CnnError> {
        let finite: Vec<Point> = cloud.iter().copied().filter(Point::is_finite).collect();
        if finite.len() < self.config.min_points {
            return Err(CnnError::TooFewPoints {
                valid: finite.len(),
                total: cloud.len(),
                required: self.config.min_points,
            });
        }
        Ok(finite)
    }

    /// Runs the network on `image` (§III.D) and decodes its pose: Γ_sym's
    /// attitude (Algorithm 1) at the ROI centre plus the offset (§III.B).
    ///
    /// # Errors
    /// Network and decoding errors.
    fn network_pose(&self, image: &DepthImage) -> Result<NetworkPose, CnnError> {
        let out = self
            .net
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .infer(&image.pixels)?;
        let delta_beta = self.config.delta_beta_deg.to_radians();
        let rotation = decode(&self.classes, &out.probs, delta_beta)?;
        // §III.B: the position is the ROI centre plus the predicted offset.
        let offset = nalgebra::Vector3::from(out.pos_offset_m.map(f64::from));
        let raw = Pose {
            rotation,
            translation: image.roi_centre + offset,
        };
        let (top_class, top_probability) = top_class(&out.probs);
        Ok(NetworkPose {
            raw,
            probs: out.probs,
            delta_beta,
            top_class,
            top_probability,
        })
    }

    /// The class table.
    pub fn classes(&self) -> &ClassTable {
        &self.classes
    }

    /// The preprocessing (N, l, trim).
    pub fn preprocess_config(&self) -> &PreprocessConfig {
        &self.preprocess
    }

    /// The settings.
    pub fn config(&self) -> &EstimatorConfig {
        &self.config
    }

    /// f_MAX (m²).
    pub fn f_max_m2(&self) -> f64 {
        self.refiner.config().f_max_m2
    }

    /// Sets f_MAX (m²).
    pub fn set_f_max_m2(&mut self, f_max_m2: f64) {
        self.refiner.set_f_max_m2(f_max_m2);
        self.config.refinement.f_max_m2 = f_max_m2;
    }

    /// What `model.json` says.
    pub fn meta(&self) -> &ModelMeta {
        &self.meta
    }

    /// The model directory.
    pub fn model_dir(&self) -> &Path {
        &self.dir
    }

    /// The engine running the network (`tract` or `ort`).
    pub fn engine(&self) -> &'static str {
        self.net
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .engine()
    }
}

/// The estimate before its refinement is reported: the network's pose
/// everywhere, f_CONV infinite, not accepted.
fn unrefined_estimate(
    net: &NetworkPose,
    points: usize,
    points_in_roi: usize,
    hypotheses_refined: usize,
    twins: TwinOutcome,
    time_ms: Timings,
) -> CnnEstimate {
    CnnEstimate {
        t_sensor_target_raw: net.raw,
        t_sensor_target: net.raw,
        f_conv_m2: f64::INFINITY,
        accepted: false,
        twins,
        top_class: net.top_class,
        top_probability: net.top_probability,
        points,
        points_in_roi,
        hypothesis: 0,
        hypotheses_refined,
        ndt_iterations: 0,
        ndt_converged: false,
        refinement_error: None,
        time_ms,
        fconv_ms: 0.0,
    }
}

/// The class of largest probability in `probs` and its probability
/// (`(0, 0.0)` for no class).
fn top_class(probs: &[f32]) -> (usize, f32) {
    probs
        .iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((0, 0.0))
}

#[cfg(test)]
#[path = "estimator_tests.rs"]
mod tests;
