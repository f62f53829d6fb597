//! The synthetic training set of seed 004 §IV.B: simulated Mid-40 frames of a
//! target under domain randomisation ([`crate::domain`]), preprocessed into
//! depth images (§III.A) with soft labels (Eq. 15) and position offsets.
//!
//! Files (contract in `/work/notes/acq-design.md`), all little-endian float32
//! `.npy`: `class_quaternions.npy` [m, 4] (w, x, y, z), `depth.npy` [count, N, N],
//! `labels.npy` [count, m], `pos_offset.npy` [count, 3] (`p − c`, sensor frame,
//! m), `attitude.npy` [count, 4] (w, x, y, z, w ≥ 0), `range_m.npy` [count];
//! `meta.json` is written last, so its presence means the set is complete.
//!
//! Determinism: sample `i` uses its own stream `LidarSimulator::frame_rng(seed,
//! i)` for every draw (conditions, materials, scan, noise, redraws), so the
//! files are identical whatever the number of threads.

use std::path::Path;
use std::sync::Arc;

use rayon::prelude::*;
use serde::Serialize;
use spacepose_lidar_sim::{LidarSimulator, ScanPattern, SensorConfig};
use spacepose_model::Target;

use crate::classes::{ClassTable, quaternion_wxyz};
use crate::decode::DEFAULT_DELTA_BETA_DEG;
use crate::domain::{DomainConfig, draw_frame};
use crate::error::{CnnError, io_err};
use crate::labels::soft_labels_into;
use crate::npy::{NpyWriter, write_f32};
use crate::preprocess::{PreprocessConfig, preprocess};

/// Frames with fewer points than this inside the ROI are re-drawn.
pub const DEFAULT_MIN_POINTS: usize = 50;
/// Draws attempted per sample before giving up.
pub const MAX_ATTEMPTS: u32 = 1000;
/// Samples generated in parallel, then written, per chunk.
const CHUNK: usize = 256;

/// What to generate.
#[derive(Debug, Clone)]
pub struct DatasetConfig {
    /// Seed of every draw.
    pub seed: u64,
    /// Number of samples.
    pub count: usize,
    /// Depth image size N.
    pub image_size: usize,
    /// Roll step Δα (deg).
    pub roll_step_deg: f64,
    /// Minimum points in the ROI.
    pub min_points: usize,
}

/// One generated sample.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// N×N depth image (row = sensor y, col = sensor x).
    pub depth: Vec<f32>,
    /// Soft label L_sym, length m.
    pub labels: Vec<f32>,
    /// `p_sensor_target − roi_centre` (m, sensor frame).
    pub pos_offset: [f32; 3],
    /// Truth `r_sensor_target` (w, x, y, z), w ≥ 0.
    pub attitude: [f32; 4],
    /// Distance of the centre of mass (m).
    pub range_m: f32,
    /// Points in the ROI.
    pub points_in_roi: usize,
    /// Frames re-drawn before this one was accepted.
    pub redraws: u32,
}

/// One simulated frame of the set, before it becomes a [`Sample`].
#[derive(Debug, Clone)]
pub struct GeneratedFrame {
    /// The cloud (sensor frame, scan order), every sensor effect applied.
    pub points: Vec<spacepose_geometry::Point>,
    /// Truth at scan end.
    pub truth: spacepose_scenario::TruthState,
    /// The depth image of `points` (§III.A).
    pub image: crate::preprocess::DepthImage,
    /// Frames re-drawn before this one was accepted.
    pub redraws: u32,
}

/// Statistics of a generated set.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DatasetStats {
    /// Frames re-drawn (too few ROI points).
    pub redraws: u64,
    /// Mean number of ROI points per accepted frame.
    pub mean_points_in_roi: f64,
    /// Largest |component| of a position offset (m); must stay below l/2.
    pub max_abs_pos_offset_m: f64,
}

/// Builds samples for one target.
#[derive(Debug)]
pub struct Generator {
    target: Arc<Target>,
    /// The target the frames are simulated of: `target` itself, or the
    /// target as built ([`Generator::outside_training`]).
    world: Arc<Target>,
    sensor: SensorConfig,
    domain: DomainConfig,
    preprocess: PreprocessConfig,
    classes: ClassTable,
    config: DatasetConfig,
}

impl Generator {
    /// A generator with the Mid-40 sensor (every effect but clutter) and the
    /// seed 004 randomisation ranges.
    ///
    /// # Errors
    /// Bad image size or roll step; a target the simulator refuses.
    pub fn new(target: Arc<Target>, config: DatasetConfig) -> Result<Self, CnnError> {
        let sensor = SensorConfig::livox_mid40();
        let fov_deg = match sensor.pattern {
            ScanPattern::Rosette { fov_deg, .. } => fov_deg,
            ScanPattern::Raster {
                fov_x_deg,
                fov_y_deg,
                ..
            } => fov_x_deg.min(fov_y_deg),
        };
        // Validates the target's materials once.
        LidarSimulator::new(target.clone(), sensor.clone())?;
        Ok(Generator {
            domain: DomainConfig::seed004(target.bounding_radius(), fov_deg),
            preprocess: PreprocessConfig::for_target(&target, config.image_size)?,
            classes: ClassTable::for_target(&target, config.roll_step_deg)?,
            world: target.clone(),
            target,
            sensor,
            config,
        })
    }

    /// This generator's frames made outside what the network was trained
    /// on (issue 25 item 3): simulated of `world` (the target as built,
    /// `spacepose_model::AsBuilt`) while the labels, the class table and
    /// the preprocessing stay the model's, by `sensor` instead of the
    /// default Mid-40, with angular rates up to `max_rate_deg_s` (seed
    /// 004 trains up to 5°/s).
    ///
    /// # Errors
    /// A sensor or target the simulator refuses.
    pub fn outside_training(
        mut self,
        world: Arc<Target>,
        sensor: SensorConfig,
        max_rate_deg_s: f64,
    ) -> Result<Self, CnnError> {
        LidarSimulator::new(world.clone(), sensor.clone())?;
        self.world = world;
        self.sensor = sensor;
        self.domain.max_rate_deg_s = max_rate_deg_s;
        Ok(self)
    }

    /// The class table.
    pub fn classes(&self) -> &ClassTable {
        &self.classes
    }

    /// The preprocessing parameters (N, l).
    pub fn preprocess_config(&self) -> &PreprocessConfig {
        &self.preprocess
    }

    /// Sample `index`, re-drawn until the ROI holds `min_points` points.
    ///
    /// # Errors
    /// [`CnnError::TooManyRedraws`], or a simulator / preprocessing error.
    pub fn sample(&self, index: u64) -> Result<Sample, CnnError> {
        let f = self.frame(index)?;
        let t = &f.truth.t_sensor_target;
        let offset = t.translation - f.image.roi_centre;
        let mut labels = vec![0.0; self.classes.len()];
        soft_labels_into(&self.classes, &t.rotation, &mut labels);
        Ok(Sample {
            depth: f.image.pixels,
            labels,
            pos_offset: [offset.x as f32, offset.y as f32, offset.z as f32],
            attitude: quaternion_wxyz(&t.rotation),
            range_m: t.translation.norm() as f32,
            points_in_roi: f.image.points_in_roi,
            redraws: f.redraws,
        })
    }

    /// The simulated frame behind sample `index` (the cloud, its truth and
    /// its depth image), re-drawn exactly as [`Generator::sample`] does: a
    /// held-out evaluation set is `frame(i)` for a seed never trained on.
    ///
    /// # Errors
    /// [`CnnError::TooManyRedraws`], or a simulator / preprocessing error.
    pub fn frame(&self, index: u64) -> Result<GeneratedFrame, CnnError> {
        let mut rng = LidarSimulator::frame_rng(self.config.seed, index);
        let half = 0.5 * self.preprocess.roi_side_m;
        for attempt in 0..MAX_ATTEMPTS {
            let draw = draw_frame(&self.domain, self.sensor.points_per_second, &mut rng);
            let mut sensor = self.sensor.clone();
            sensor.integration_time_s = draw.integration_time_s;
            let sim = LidarSimulator::new(self.world.clone(), sensor)?;
            let frame = sim.try_simulate(&draw.truth, &mut rng)?;
            if frame.points.len() < self.config.min_points {
                continue;
            }
            let image = preprocess(&frame.points, &self.preprocess)?;
            let offset = draw.truth.t_sensor_target.translation - image.roi_centre;
            if image.points_in_roi < self.config.min_points || offset.amax() >= half {
                continue;
            }
            return Ok(GeneratedFrame {
                points: frame.points,
                truth: draw.truth,
                image,
                redraws: attempt,
            });
        }
        Err(CnnError::TooManyRedraws {
            index,
            min_points: self.config.min_points,
            attempts: MAX_ATTEMPTS,
        })
    }

    /// Generates the whole set into `dir` (created if missing), in parallel on
    /// the current rayon pool; `progress(k)` is called as `k` more samples are done.
    ///
    /// # Errors
    /// I/O errors and the errors of [`Generator::sample`].
    pub fn write(
        &self,
        dir: &Path,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<DatasetStats, CnnError> {
        std::fs::create_dir_all(dir).map_err(io_err(dir))?;
        let meta_path = dir.join("meta.json");
        if meta_path.exists() {
            std::fs::remove_file(&meta_path).map_err(io_err(&meta_path))?;
        }
        let (count, n, m) = (
            self.config.count,
            self.preprocess.image_size,
            self.classes.len(),
        );
        let quats: Vec<f32> = self.classes.quaternions_wxyz().concat();
        write_f32(&dir.join("class_quaternions.npy"), &[m, 4], &quats)?;
        let mut depth = NpyWriter::create(&dir.join("depth.npy"), &[count, n, n])?;
        let mut labels = NpyWriter::create(&dir.join("labels.npy"), &[count, m])?;
        let mut pos = NpyWriter::create(&dir.join("pos_offset.npy"), &[count, 3])?;
        let mut att = NpyWriter::create(&dir.join("attitude.npy"), &[count, 4])?;
        let mut range = NpyWriter::create(&dir.join("range_m.npy"), &[count])?;
        let (mut redraws, mut points, mut max_offset) = (0u64, 0f64, 0f64);
        for start in (0..count).step_by(CHUNK) {
            let end = (start + CHUNK).min(count);
            let samples: Vec<Sample> = (start..end)
                .into_par_iter()
                .map(|i| {
                    let s = self.sample(i as u64);
                    progress(1);
                    s
                })
                .collect::<Result<_, _>>()?;
            for s in &samples {
                depth.write(&s.depth)?;
                labels.write(&s.labels)?;
                pos.write(&s.pos_offset)?;
                att.write(&s.attitude)?;
                range.write(&[s.range_m])?;
                redraws += u64::from(s.redraws);
                points += s.points_in_roi as f64;
                max_offset = s
                    .pos_offset
                    .iter()
                    .fold(max_offset, |a, v| a.max(f64::from(v.abs())));
            }
        }
        for w in [depth, labels, pos, att, range] {
            w.finish()?;
        }
        let stats = DatasetStats {
            redraws,
            mean_points_in_roi: points / count.max(1) as f64,
            max_abs_pos_offset_m: max_offset,
        };
        let meta = self.meta(stats);
        std::fs::write(&meta_path, serde_json::to_string_pretty(&meta)?)
            .map_err(io_err(&meta_path))?;
        Ok(stats)
    }

    fn meta(&self, stats: DatasetStats) -> Meta {
        Meta {
            target: self.target.name().to_string(),
            seed: self.config.seed,
            count: self.config.count,
            image_size: self.preprocess.image_size,
            roi_side_m: self.preprocess.roi_side_m,
            classes: self.classes.len(),
            classes_before_symmetry: self.classes.full_count(),
            roll_step_deg: self.classes.roll_step_rad().to_degrees(),
            sigma_deg: self.classes.sigma_rad().to_degrees(),
            symmetry_order: self.classes.symmetries().len(),
            delta_beta_deg: DEFAULT_DELTA_BETA_DEG,
            trim: self.preprocess.trim,
            min_points: self.config.min_points,
            depth_layout: "depth[i, row, col]: row = sensor +y (down), col = sensor +x (right); \
                           value = ((z - c_z) + l/2) / l averaged per pixel (Eq. 3), 0 = empty; \
                           flips/rotations of the image change the attitude",
            sensor: "Livox Mid-40 rosette, all effects but clutter",
            domain: self.domain,
            stats,
            generator: format!("spacepose {}", env!("CARGO_PKG_VERSION")),
        }
    }
}

/// `meta.json`.
#[derive(Debug, Serialize)]
struct Meta {
    target: String,
    seed: u64,
    count: usize,
    image_size: usize,
    roi_side_m: f64,
    classes: usize,
    classes_before_symmetry: usize,
    roll_step_deg: f64,
    sigma_deg: f64,
    symmetry_order: usize,
    delta_beta_deg: f64,
    trim: f64,
    min_points: usize,
    depth_layout: &'static str,
    sensor: &'static str,
    domain: DomainConfig,
    stats: DatasetStats,
    generator: String,
}

#[cfg(test)]
#[path = "dataset_tests.rs"]
mod tests;
