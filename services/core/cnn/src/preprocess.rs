//! Seed 004 §III.A: trimmed centroid (Eqs. 1-2), cubic region of interest of
//! side `l` around it, and the parallel projection along the boresight to an
//! N×N depth image (Eq. 3).
//!
//! # Image layout
//! `pixels[row * N + col]`, row-major. `col` grows with the sensor `+x`
//! (right), `row` with the sensor `+y` (down), so the image is what the
//! sensor sees with the usual image orientation. A flipped or rotated image
//! is a *different attitude*: image flips are not label-preserving
//! augmentations. A pixel holds the mean of `((p)_z − c_z + l/2) / l` over the
//! points that fall in it (Eq. 3): near surfaces are small values, far ones
//! close to 1, and an empty pixel is exactly 0 (a point exactly on the near
//! face of the ROI is clamped to the smallest positive `f32` so it stays
//! distinguishable from an empty pixel).
//!
//! # Choice of N (measured by `cargo bench -p spacepose-cnn --bench preprocess`)
//! Preprocessing one simulated 10,623-point `deos` frame at 10 m on one core,
//! Criterion mean, measured while the machine ran the dataset generation
//! (load ≈ 6 on 2 cores, so absolute values are inflated and noisy):
//! N = 64: 0.77 ms, 96: 0.92 ms, 128: 0.81 ms, 224: 0.65 ms. There is no
//! trend with N inside the noise: the trimmed centroid (three O(n)
//! selections over all points) and the per-point loop dominate; N only adds
//! the zeroing and the per-pixel division of N² cells (50k at 224).
//! Preprocessing never decides N; the CNN does: training cost grows with N²
//! (MobileNetV3-Small 0.5 on 2 cores: 0.71 ms/image at 64 vs ~1 ms at 96,
//! `/work/shared/notes/cnn-and-onnx.md`) and inference too (tract 0.48 ms at
//! 64, 3.1 ms at 224). With a ~1 h training budget on two shared cores,
//! N = 64 is the default ([`DEFAULT_IMAGE_SIZE`]); with l = 4 m a pixel is
//! then 6.25 cm, finer than the 15 cm success threshold and comparable to
//! the Mid-40 point spacing at 10-20 m.

use nalgebra::Vector3;
use spacepose_geometry::centroid::trimmed_centroid_with_scratch;
use spacepose_geometry::{DEFAULT_TRIM, Point};
use spacepose_model::Target;

use crate::error::CnnError;

/// Default depth image size N (see the module documentation for the trade-off).
pub const DEFAULT_IMAGE_SIZE: usize = 64;
/// Smallest supported image size.
pub const MIN_IMAGE_SIZE: usize = 64;
/// Largest supported image size (the paper's 224).
pub const MAX_IMAGE_SIZE: usize = 224;

/// ROI side `l` as a multiple of the target's bounding radius: `l = 2.5 r`.
///
/// The trimmed centroid lies inside the interquartile box of the visible
/// points, and every visible point is within `r` of the centre of mass, so a
/// half side of `1.25 r` keeps all target points in practice (the test
/// `roi_keeps_the_whole_target` measures it over random attitudes) and the
/// centre-of-mass offset `p − c` (at most ≈ r, when only one end face is
/// seen) well inside the `tanh · l/2` range of the position head. For `deos`
/// (r = 1.6008 m, 2.6 m long, 1.96 m across) this gives l = 4.0 m.
pub const ROI_SIDE_OVER_RADIUS: f64 = 2.5;

/// The ROI side `l` for a target (m), see [`ROI_SIDE_OVER_RADIUS`].
pub fn roi_side_for(target: &Target) -> f64 {
    // Rounded to the centimetre so the value reads well in meta.json.
    (ROI_SIDE_OVER_RADIUS * target.bounding_radius() * 100.0).round() / 100.0
}

/// Parameters of the preprocessing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreprocessConfig {
    /// Image size N (pixels per side).
    pub image_size: usize,
    /// ROI side l (m).
    pub roi_side_m: f64,
    /// Trimming factor of the centroid (0.25 in seed 004).
    pub trim: f64,
}

impl PreprocessConfig {
    /// The configuration for `target` at image size `image_size`, trim 25 %.
    ///
    /// # Errors
    /// [`CnnError::ImageSize`] outside `MIN_IMAGE_SIZE..=MAX_IMAGE_SIZE`.
    pub fn for_target(target: &Target, image_size: usize) -> Result<Self, CnnError> {
        let config = PreprocessConfig {
            image_size,
            roi_side_m: roi_side_for(target),
            trim: DEFAULT_TRIM,
        };
        config.validate()?;
        Ok(config)
    }

    /// Checks the image size and the ROI side.
    ///
    /// # Errors
    /// [`CnnError::ImageSize`] or [`CnnError::InvalidParameter`].
    pub fn validate(&self) -> Result<(), CnnError> {
        if !(MIN_IMAGE_SIZE..=MAX_IMAGE_SIZE).contains(&self.image_size) {
            return Err(CnnError::ImageSize {
                got: self.image_size,
                min: MIN_IMAGE_SIZE,
                max: MAX_IMAGE_SIZE,
            });
        }
        if !(self.roi_side_m.is_finite() && self.roi_side_m > 0.0) {
            return Err(CnnError::InvalidParameter {
                name: "roi_side_m",
                value: self.roi_side_m,
            });
        }
        Ok(())
    }
}

/// A depth image with the ROI it was projected from.
#[derive(Debug, Clone, PartialEq)]
pub struct DepthImage {
    /// N, pixels per side.
    pub size: usize,
    /// N×N values in [0, 1], row-major (row = sensor y, col = sensor x), 0 = empty.
    pub pixels: Vec<f32>,
    /// The trimmed centroid `c`, centre of the ROI, in the sensor frame (m).
    pub roi_centre: Vector3<f64>,
    /// Number of points inside the ROI (projected).
    pub points_in_roi: usize,
}

/// Preprocesses one cloud (sensor frame) into a depth image (seed 004 §III.A).
///
/// # Errors
/// [`CnnError::EmptyCloud`] for no point, [`CnnError::Centroid`] for a
/// non-finite coordinate, configuration errors from [`PreprocessConfig::validate`].
pub fn preprocess(points: &[Point], config: &PreprocessConfig) -> Result<DepthImage, CnnError> {
    config.validate()?;
    if points.is_empty() {
        return Err(CnnError::EmptyCloud);
    }
    // Eqs. (1)-(2): the trimmed centroid.
    let c = trimmed_centroid_with_scratch(points, config.trim, &mut Vec::new())?;
    let n = config.image_size;
    let l = config.roi_side_m;
    let half = 0.5 * l;
    let scale = n as f64 / l;
    let mut sums = vec![0.0f32; n * n];
    let mut counts = vec![0u32; n * n];
    let mut inside = 0usize;
    for p in points {
        let d = p.position() - c;
        // Cubic ROI: every coordinate of p − c in [−l/2, l/2).
        if !(d.iter().all(|v| (-half..half).contains(v))) {
            continue;
        }
        // Parallel projection on the (x, y) plane; both indices are in 0..n
        // because the offsets are in [0, l). `min` guards rounding at the edge.
        let col = (((d.x + half) * scale) as usize).min(n - 1);
        let row = (((d.y + half) * scale) as usize).min(n - 1);
        // Eq. (3): ((p)_z − c_z + l/2) / l.
        let v = ((d.z + half) / l) as f32;
        sums[row * n + col] += v;
        counts[row * n + col] += 1;
        inside += 1;
    }
    let pixels = sums
        .iter()
        .zip(&counts)
        .map(|(&s, &k)| {
            if k == 0 {
                0.0
            } else {
                (s / k as f32).clamp(f32::MIN_POSITIVE, 1.0)
            }
        })
        .collect();
    Ok(DepthImage {
        size: n,
        pixels,
        roi_centre: c,
        points_in_roi: inside,
    })
}

#[cfg(test)]
#[path = "preprocess_tests.rs"]
mod tests;
