//! The visibility gate (not in the papers; `docs/design/visibility-gate.md`):
//! before a frame is registered, the points that lie behind every surface
//! the model can show along their line of sight, at the filter's predicted
//! pose, are dropped.
//!
//! Why: a lidar beam that meets a mirror-like surface (MLI, solar-cell
//! glass) goes on to a second surface, and the echo comes back along the
//! same path, so the sensor reports a point along the first ray but at the
//! length of the whole path: behind the mirror (seed 004 §IV.A, which the
//! simulator models). A surface return can never lie behind the first
//! surface along its ray. On generated targets with large MLI faces and
//! appendages, these ghosts made up about 30 % of the cropped points in
//! some attitudes, and they are coherent (a mirror image of part of the
//! target), so NDT followed them: every development zoo design at scenario
//! seed 2023 lost the track at frames 44-51, and none did with the
//! simulator's reflections switched off.
//!
//! The test is conservative: a point is dropped only when its range exceeds,
//! by `tolerance_m`, every first-surface range within a disc about its ray
//! that covers the pose's uncertainty at the point's depth, and a disc
//! with no surface (beside the target) keeps it
//! ([`DepthImage::may_be_surface`]). It uses the prediction and the model
//! only, never the truth.

use crate::depth_image::DepthImage;
use crate::error::TrackError;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use spacepose_filter::{MotionCompensation, Prediction};
use spacepose_geometry::Point;
use std::collections::HashSet;

/// The gate's configuration (the `[tracker.visibility]` table).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VisibilityConfig {
    /// Drop the points behind the model's first surface before registration.
    pub enabled: bool,
    /// How far behind every first surface near its ray a point must lie to be
    /// dropped (m). A sensor length, not scaled with the target: it covers
    /// the range noise (σ 2 cm), the echoes that mix two surfaces and land
    /// just behind the first, and a model a few centimetres off, while a
    /// mirror ghost lies a surface-to-surface distance behind (0.3-3 m on
    /// the zoo). Default 0.15 m. On development design `zoo:1001` (seed
    /// 2023, frames 44-80, prediction 2° off) it dropped 60-100 % of the
    /// ghosts and at most 5 of 21,000 points of the same frames simulated
    /// without reflections; 0.87 m (0.3 m scaled by that design's ℓ) dropped
    /// under 0.3 % of the ghosts.
    pub tolerance_m: f64,
    /// Attitude error (deg) the neighbourhood allows for at the least; the
    /// prediction's 3σ when that is larger. Default 1°, above the
    /// prediction's error in steady tracking (0.2-1°). On development design
    /// `zoo:1001` (scenario seed 2023, frames 44-80, predicted pose 2° off
    /// the truth) no surface return was dropped with 1°, and 60-95 % of the
    /// reflection ghosts were; with 3° the widened image reached the deep
    /// side walls almost everywhere and caught under 3 % of them.
    pub pose_allowance_deg: f64,
    /// When the gate would drop more than this fraction of the points, it
    /// drops none: the prediction, not the frame, is then likely wrong, and
    /// the registration must see everything. Default 0.5.
    pub max_dropped_fraction: f64,
    /// In the start-up (the filter's rate still unknown:
    /// `TrackerConfig::start_up_blur_deg`), gate the cloud again at the
    /// fitted pose after the registration, and register again on what it
    /// keeps when that drops `refit_min_fraction` of the cloud the gate at
    /// the prediction kept: a prediction a scan's
    /// turn off, with its wide neighbourhood, keeps ghosts that a fit a
    /// degree off sees (`docs/design/echo-separation.md`). Not after the
    /// start-up: there the prediction is as good as a fit, and a second
    /// registration only moved the pose by its noise. Default on.
    pub refit: bool,
    /// See `refit`. Default 0.01: a hundredth of the cloud.
    pub refit_min_fraction: f64,
    /// Also drop the points outside the model's bounding box (body frame)
    /// grown by the neighbourhood's margin and `tolerance_m`: no surface
    /// return lies there at the prediction. At a prediction as wide as the
    /// start-up's the box grows past the target and removes nothing; at
    /// the fit of a start-up frame (`refit`) it removes what holds the
    /// target (a facility's robot arm), which the crop's sphere keeps until
    /// the attitude is known. Default on.
    pub outside_box: bool,
}

impl Default for VisibilityConfig {
    fn default() -> Self {
        Self {
            enabled: true,
            tolerance_m: 0.15,
            pose_allowance_deg: 1.0,
            max_dropped_fraction: 0.5,
            refit: true,
            refit_min_fraction: 0.01,
            outside_box: true,
        }
    }
}

impl VisibilityConfig {
    /// Fails on a non-finite or out-of-range value.
    pub fn validate(&self) -> Result<(), TrackError> {
        let ok = self.tolerance_m.is_finite()
            && self.tolerance_m >= 0.0
            && self.pose_allowance_deg.is_finite()
            && (0.0..90.0).contains(&self.pose_allowance_deg)
            && (0.0..=1.0).contains(&self.max_dropped_fraction)
            && (0.0..=1.0).contains(&self.refit_min_fraction);
        if ok {
            Ok(())
        } else {
            Err(TrackError::InvalidConfig(format!(
                "visibility: tolerance_m >= 0, pose_allowance_deg in [0, 90), \
                 max_dropped_fraction and refit_min_fraction in [0, 1], all finite: {self:?}"
            )))
        }
    }
}

/// What the gate did with a frame.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Gated {
    /// The points kept (all of them when the gate did not apply).
    pub points: Vec<Point>,
    /// Points found behind the model, or outside its box with
    /// `outside_box` (dropped unless `overruled`).
    pub behind: usize,
    /// More than `max_dropped_fraction` were behind, so none was dropped.
    pub overruled: bool,
}

/// Whether a point can be a surface return at the prediction.
struct SurfaceTest {
    image: DepthImage,
    compensation: Option<MotionCompensation>,
    margin_m: f64,
    tolerance_m: f64,
    t_target_sensor: spacepose_geometry::Pose,
    grown_box: Option<(Vector3<f64>, Vector3<f64>)>,
}

impl SurfaceTest {
    /// False when the point, carried to the scan end, lies behind every
    /// first surface near its ray or outside the grown box; a
    /// non-finite point is left to the registration, which skips it.
    fn may_be_surface(&self, p: &Point) -> bool {
        let x = p.position();
        let x = self
            .compensation
            .as_ref()
            .map_or(x, |c| c.position_at_end(&x, p.t));
        if !x.iter().all(|c| c.is_finite()) {
            return true;
        }
        if let Some((lo, hi)) = &self.grown_box {
            let b = self.t_target_sensor.transform(&x);
            if (0..3).any(|i| b[i] < lo[i] || b[i] > hi[i]) {
                return false;
            }
        }
        self.image
            .may_be_surface(&x, self.margin_m, self.tolerance_m)
    }
}

/// The model cloud the gate renders: the tracker's model cloud thinned to
/// one point per third of an NDT cell, so a frame's depth image costs about
/// the same for every target above deos's size (the cell grows with the
/// target: ℓ = 0.018 √A), about 28,000 points for deos.
#[derive(Debug, Clone)]
pub struct VisibilityModel {
    points_target: Vec<Vector3<f64>>,
    spacing_m: f64,
    radius_m: f64,
    /// The model's bounding box in the body frame.
    bounds: (Vector3<f64>, Vector3<f64>),
}

impl VisibilityModel {
    /// One point of `model_target` (body frame) per cube of `spacing_m`.
    pub fn new(model_target: &[Vector3<f64>], spacing_m: f64) -> Self {
        let mut seen = HashSet::new();
        let points_target: Vec<Vector3<f64>> = model_target
            .iter()
            .filter(|p| p.iter().all(|c| c.is_finite()))
            .filter(|p| seen.insert(p.map(|c| (c / spacing_m).floor() as i64)))
            .copied()
            .collect();
        let radius_m = model_target
            .iter()
            .map(|p| p.norm())
            .filter(|r| r.is_finite())
            .fold(0.0, f64::max);
        let bounds = points_target.iter().fold(
            (
                Vector3::repeat(f64::INFINITY),
                Vector3::repeat(f64::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.inf(p), hi.sup(p)),
        );
        Self {
            points_target,
            spacing_m,
            radius_m,
            bounds,
        }
    }

    /// Number of points rendered per frame.
    pub fn len(&self) -> usize {
        self.points_target.len()
    }

    /// True for a model with no point.
    pub fn is_empty(&self) -> bool {
        self.points_target.is_empty()
    }

    /// The `points` that are not behind the model at `prediction`. Points
    /// not yet `at_scan_end` are tested where the prediction's motion puts
    /// them at the scan end (Eq. 12 of seed 000) and kept as measured.
    /// Runs on the voxel-filtered cloud: a voxel (2 cm) holds a ghost or a
    /// surface return, hardly both, and the test then costs a few
    /// thousand lookups instead of the raw frame's tens of thousands.
    pub fn gate(
        &self,
        points: Vec<Point>,
        at_scan_end: bool,
        prediction: &Prediction,
        config: &VisibilityConfig,
    ) -> Result<Gated, TrackError> {
        let image = if config.enabled && !self.is_empty() {
            DepthImage::render(
                &self.points_target,
                self.spacing_m,
                self.radius_m,
                &prediction.pose,
            )
        } else {
            None
        };
        let Some(image) = image else {
            return Ok(Gated {
                points,
                ..Gated::default()
            });
        };
        let compensation = match at_scan_end {
            true => None,
            false => Some(MotionCompensation::from_prediction(prediction)?),
        };
        let margin_m = self.margin_m(prediction, config);
        let grow = margin_m + config.tolerance_m;
        let test = SurfaceTest {
            image,
            compensation,
            margin_m,
            tolerance_m: config.tolerance_m,
            t_target_sensor: prediction.pose.inverse(),
            grown_box: config.outside_box.then(|| {
                (
                    self.bounds.0.add_scalar(-grow),
                    self.bounds.1.add_scalar(grow),
                )
            }),
        };
        let keep: Vec<bool> = points.iter().map(|p| test.may_be_surface(p)).collect();
        let behind = keep.iter().filter(|k| !**k).count();
        let overruled = behind as f64 > config.max_dropped_fraction * points.len() as f64;
        let points = if overruled || behind == 0 {
            points
        } else {
            points
                .into_iter()
                .zip(&keep)
                .filter_map(|(p, k)| k.then_some(p))
                .collect()
        };
        Ok(Gated {
            points,
            behind,
            overruled,
        })
    }

    /// How far (m) the surface may be displaced from where the prediction
    /// puts it: the attitude allowance (or the prediction's 3σ) at the
    /// bounding radius, plus the prediction's 3σ in position.
    fn margin_m(&self, prediction: &Prediction, config: &VisibilityConfig) -> f64 {
        let (sigma_rot, sigma_pos) = sigmas(prediction);
        let allow = config.pose_allowance_deg.to_radians().max(3.0 * sigma_rot);
        self.radius_m * allow.min(1.0).tan() + 3.0 * sigma_pos
    }
}

/// The prediction's worst-axis attitude σ (rad) and its position σ (m),
/// 0 where not finite.
fn sigmas(prediction: &Prediction) -> (f64, f64) {
    let c = &prediction.covariance;
    let finite_or_zero = |v: f64| if v.is_finite() { v.max(0.0) } else { 0.0 };
    let sigma_rot = finite_or_zero(c[(0, 0)].max(c[(1, 1)]).max(c[(2, 2)])).sqrt();
    let sigma_pos = finite_or_zero(c[(3, 3)] + c[(4, 4)] + c[(5, 5)]).sqrt();
    (sigma_rot, sigma_pos)
}

#[cfg(test)]
#[path = "visibility_tests.rs"]
mod tests;
