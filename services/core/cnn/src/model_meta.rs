//! `model.json`, written by `tools/train` next to `model.onnx`: the training
//! set's `meta.json` (N, l, m, Δα, σ, symmetry) plus training metrics. The
//! estimator reads the first part and refuses a model trained for another
//! preprocessing or class table.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::classes::ClassTable;
use crate::error::{CnnError, io_err};
use crate::preprocess::PreprocessConfig;

/// File name of the network in a model directory.
pub const MODEL_ONNX: &str = "model.onnx";
/// File name of the metadata in a model directory.
pub const MODEL_JSON: &str = "model.json";

/// Relative tolerance on the real-valued fields (l, Δα, σ, trim).
const TOLERANCE: f64 = 1e-6;

/// What the estimator needs from `model.json` (other keys are ignored).
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct ModelMeta {
    /// Target the model was trained for.
    pub target: String,
    /// Depth image size N.
    pub image_size: usize,
    /// ROI side l (m).
    pub roi_side_m: f64,
    /// Number of classes m (after the symmetry reduction).
    pub classes: usize,
    /// Number of classes before the symmetry reduction.
    #[serde(default)]
    pub classes_before_symmetry: Option<usize>,
    /// Roll step Δα (deg).
    pub roll_step_deg: f64,
    /// σ of the soft labels (deg).
    pub sigma_deg: f64,
    /// Order of the target's symmetry group.
    pub symmetry_order: usize,
    /// Trim of the centroid.
    #[serde(default)]
    pub trim: Option<f64>,
}

impl ModelMeta {
    /// Reads `dir/model.json`.
    ///
    /// # Errors
    /// [`CnnError::ModelDir`] when the file is missing, [`CnnError::Io`] or
    /// [`CnnError::ModelMeta`] when it cannot be read or parsed.
    pub fn read(dir: &Path) -> Result<Self, CnnError> {
        let path = dir.join(MODEL_JSON);
        if !path.is_file() {
            return Err(CnnError::ModelDir {
                path: dir.to_path_buf(),
                reason: format!("no {MODEL_JSON} (expected {MODEL_JSON} + {MODEL_ONNX})"),
            });
        }
        let text = std::fs::read_to_string(&path).map_err(io_err(&path))?;
        serde_json::from_str(&text).map_err(|e| CnnError::ModelMeta {
            path,
            reason: e.to_string(),
        })
    }

    /// Checks the model against the crate's preprocessing and class table
    /// for the target in use.
    ///
    /// # Errors
    /// [`CnnError::ModelMismatch`] naming the first field that differs.
    pub fn check(
        &self,
        path: &Path,
        target: &str,
        preprocess: &PreprocessConfig,
        classes: &ClassTable,
    ) -> Result<(), CnnError> {
        let mismatch = |field: &'static str, model: String, expected: String| {
            Err(CnnError::ModelMismatch {
                path: path.to_path_buf(),
                field,
                model,
                expected,
            })
        };
        let close = |a: f64, b: f64| (a - b).abs() <= TOLERANCE * b.abs().max(1.0);
        if self.target != target {
            return mismatch("target", self.target.clone(), target.to_string());
        }
        if self.image_size != preprocess.image_size {
            return mismatch(
                "image_size",
                self.image_size.to_string(),
                preprocess.image_size.to_string(),
            );
        }
        if !close(self.roi_side_m, preprocess.roi_side_m) {
            return mismatch(
                "roi_side_m",
                self.roi_side_m.to_string(),
                preprocess.roi_side_m.to_string(),
            );
        }
        if let Some(trim) = self.trim
            && !close(trim, preprocess.trim)
        {
            return mismatch("trim", trim.to_string(), preprocess.trim.to_string());
        }
        let roll_step_deg = classes.roll_step_rad().to_degrees();
        if !close(self.roll_step_deg, roll_step_deg) {
            return mismatch(
                "roll_step_deg",
                self.roll_step_deg.to_string(),
                roll_step_deg.to_string(),
            );
        }
        if self.classes != classes.len() {
            return mismatch(
                "classes",
                self.classes.to_string(),
                classes.len().to_string(),
            );
        }
        if let Some(full) = self.classes_before_symmetry
            && full != classes.full_count()
        {
            return mismatch(
                "classes_before_symmetry",
                full.to_string(),
                classes.full_count().to_string(),
            );
        }
        let sigma_deg = classes.sigma_rad().to_degrees();
        if !close(self.sigma_deg, sigma_deg) {
            return mismatch(
                "sigma_deg",
                self.sigma_deg.to_string(),
                sigma_deg.to_string(),
            );
        }
        if self.symmetry_order != classes.symmetries().len() {
            return mismatch(
                "symmetry_order",
                self.symmetry_order.to_string(),
                classes.symmetries().len().to_string(),
            );
        }
        Ok(())
    }
}

/// `dir/model.onnx`, which must exist.
///
/// # Errors
/// [`CnnError::ModelDir`] when the directory or the file is missing.
pub fn model_onnx_path(dir: &Path) -> Result<PathBuf, CnnError> {
    if !dir.is_dir() {
        return Err(CnnError::ModelDir {
            path: dir.to_path_buf(),
            reason: "not a directory".into(),
        });
    }
    let path = dir.join(MODEL_ONNX);
    if !path.is_file() {
        return Err(CnnError::ModelDir {
            path: dir.to_path_buf(),
            reason: format!("no {MODEL_ONNX} (the trained network)"),
        });
    }
    Ok(path)
}
