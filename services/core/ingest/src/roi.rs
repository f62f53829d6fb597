//! Region of interest of one frame (seed 000 §4.1: "points which do not
//! belong to the spacecraft mockup are cropped out from the point cloud in a
//! pre-processing step").
//!
//! Always a range gate `[min_range, max_range]`. With a trusted prediction of
//! the target centre, also a sphere about the centre predicted at scan end of
//! radius `bounding radius + margin + |v| (scan_end - scan_start)` (the last
//! term covers the target's own motion during the scan). When the prediction
//! also carries an attitude and a body box is configured, the point must lie
//! in the body box grown by the margin, at the pose predicted for its own
//! timestamp (constant velocity and angular velocity, seed 000 Eq. 8-9):
//! this removes the robot arm that holds the target, which the sphere keeps.
//! Without a prediction (before acquisition, or when it is stale), an
//! optional static box.

use crate::config::{AxisBox, IngestConfig};
use crate::detect::{Detection, detect};
use nalgebra::{Matrix3, Rotation3, Vector3};
use spacepose_geometry::{Point, so3};

/// Rotations tabulated over the scan for the body-box test: at 10°/s over a
/// 0.72 s scan, neighbouring entries differ by 0.24°, < 1 cm at 2 m.
const ROTATION_STEPS: usize = 32;

/// The motion state of the target as known before the frame: the filter's
/// position and velocity of the centre of mass at `t_s`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TargetPrediction {
    /// Time of the state (s, sensor clock).
    pub t_s: f64,
    /// Centre of mass in the sensor frame at `t_s` (m).
    pub p_sensor_target: Vector3<f64>,
    /// Velocity of the centre of mass relative to the sensor, sensor frame (m/s).
    pub v_sensor: Vector3<f64>,
    /// Attitude and angular velocity at `t_s`, when known.
    pub attitude: Option<AttitudePrediction>,
}

/// The attitude part of a [`TargetPrediction`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudePrediction {
    /// Target body → sensor rotation at `t_s`.
    pub r_sensor_target: Rotation3<f64>,
    /// Angular velocity of the target relative to the sensor, body frame
    /// (rad/s): `R(t) = R(t_s) Exp(ω (t - t_s))` (seed 000 Eq. 9).
    pub w_target: Vector3<f64>,
    /// Attitude uncertainty at `t_s`, worst axis (rad, 1σ).
    pub sigma_rot_rad: f64,
    /// Angular-velocity uncertainty, worst axis (rad/s, 1σ).
    pub sigma_w_radps: f64,
}

impl AttitudePrediction {
    /// Worst-axis attitude uncertainty propagated to `dt_s` after `t_s`
    /// (rad, 1σ): `sqrt(σ_R² + (σ_ω dt)²)`.
    pub fn sigma_at(&self, dt_s: f64) -> f64 {
        (self.sigma_rot_rad.powi(2) + (self.sigma_w_radps * dt_s).powi(2)).sqrt()
    }
}

impl TargetPrediction {
    /// True when every number is finite.
    pub fn is_finite(&self) -> bool {
        let finite = |v: &Vector3<f64>| v.iter().all(|x| x.is_finite());
        self.t_s.is_finite()
            && finite(&self.p_sensor_target)
            && finite(&self.v_sensor)
            && self.attitude.as_ref().is_none_or(|a| {
                finite(&a.w_target)
                    && a.r_sensor_target.matrix().iter().all(|x| x.is_finite())
                    && a.sigma_rot_rad.is_finite()
                    && a.sigma_w_radps.is_finite()
            })
    }

    /// Attitude propagated to `t_s` (seed 000 Eq. 9), if known.
    pub fn rotation_at(&self, t_s: f64) -> Option<Rotation3<f64>> {
        self.attitude
            .as_ref()
            .map(|a| a.r_sensor_target * so3::exp(&(a.w_target * (t_s - self.t_s))))
    }

    /// Centre of mass propagated with constant velocity to `t_s` (m).
    pub fn centre_at(&self, t_s: f64) -> Vector3<f64> {
        self.p_sensor_target + self.v_sensor * (t_s - self.t_s)
    }
}

/// Which region of interest cropped a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RoiKind {
    /// Range gate and the sphere about the predicted centre.
    Predicted,
    /// Range gate, sphere, and the body box at the predicted pose.
    PredictedWithAttitude,
    /// Range gate and the configured static box (no trusted prediction).
    StaticBox,
    /// No trusted prediction: the target found in the frame
    /// ([`crate::detect`]), within the static box if one is configured.
    Detected,
    /// Range gate only (no trusted prediction, no static box).
    RangeOnly,
}

/// Why a prediction given with a frame was not used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PredictionIssue {
    /// A field is NaN or infinite.
    NonFinite,
    /// Older (or newer) than `max_prediction_age_s` at scan end.
    Stale,
}

/// The region of interest of one frame, ready for per-point tests.
#[derive(Debug, Clone)]
pub struct Roi {
    min_range2: f64,
    max_range2: f64,
    sphere: Option<(Vector3<f64>, f64)>,
    static_box: Option<AxisBox>,
    oriented: Option<OrientedBox>,
    detection: Option<Detection>,
}

/// The body box swept along the predicted trajectory during the scan.
#[derive(Debug, Clone, Copy, PartialEq)]
struct OrientedBox {
    /// Grown body box.
    body_box: AxisBox,
    scan_start_s: f64,
    /// Time between two tabulated rotations (s); 0 for an instantaneous scan.
    step_s: f64,
    /// `R(t_k)ᵀ` (sensor → body) at `t_k = scan_start + k step`.
    r_target_sensor: [Matrix3<f64>; ROTATION_STEPS],
    /// Predicted centre at scan end and velocity.
    centre_end: Vector3<f64>,
    scan_end_s: f64,
    v_sensor: Vector3<f64>,
}

impl OrientedBox {
    fn new(
        body_box: AxisBox,
        pred: &TargetPrediction,
        scan_start_s: f64,
        scan_end_s: f64,
    ) -> Option<OrientedBox> {
        pred.attitude?;
        let step_s = (scan_end_s - scan_start_s).max(0.0) / (ROTATION_STEPS - 1) as f64;
        let mut r_target_sensor = [Matrix3::identity(); ROTATION_STEPS];
        for (k, r) in r_target_sensor.iter_mut().enumerate() {
            let t = scan_start_s + k as f64 * step_s;
            *r = pred.rotation_at(t)?.matrix().transpose();
        }
        Some(OrientedBox {
            body_box,
            scan_start_s,
            step_s,
            r_target_sensor,
            centre_end: pred.centre_at(scan_end_s),
            scan_end_s,
            v_sensor: pred.v_sensor,
        })
    }

    #[inline]
    fn contains(&self, v: &Vector3<f64>, t_s: f64) -> bool {
        let k = if self.step_s > 0.0 {
            // Nearest tabulated time, clamped to the scan (NaN → 0).
            (((t_s - self.scan_start_s) / self.step_s).round().max(0.0) as usize)
                .min(ROTATION_STEPS - 1)
        } else {
            ROTATION_STEPS - 1
        };
        let centre = self.centre_end + self.v_sensor * (t_s - self.scan_end_s);
        let body = self.r_target_sensor[k] * (v - centre);
        self.body_box.contains([body.x, body.y, body.z])
    }
}

impl Roi {
    /// The region for a scan over `[scan_start_s, scan_end_s]`, and why the
    /// prediction was dropped if it was.
    pub fn for_frame(
        config: &IngestConfig,
        prediction: Option<&TargetPrediction>,
        scan_start_s: f64,
        scan_end_s: f64,
    ) -> (Roi, Option<PredictionIssue>) {
        let mut roi = Roi {
            min_range2: config.min_range_m * config.min_range_m,
            max_range2: config.max_range_m * config.max_range_m,
            sphere: None,
            static_box: config.static_box,
            oriented: None,
            detection: None,
        };
        let Some(pred) = prediction else {
            return (roi, None);
        };
        if !pred.is_finite() {
            return (roi, Some(PredictionIssue::NonFinite));
        }
        // False for a NaN age too.
        let fresh = (scan_end_s - pred.t_s).abs() <= config.max_prediction_age_s;
        if !fresh {
            return (roi, Some(PredictionIssue::Stale));
        }
        let centre = pred.centre_at(scan_end_s);
        let radius = config.target_bounding_radius_m
            + config.margin_m
            + pred.v_sensor.norm() * (scan_end_s - scan_start_s).max(0.0);
        roi.sphere = Some((centre, radius * radius));
        roi.static_box = None;
        // The body box sits at the predicted attitude: it is only used when
        // that attitude is known well enough that a 3σ error moves the
        // target's farthest point by less than the margin. Before the filter
        // has learnt the spin (seed 000 §5.2) a misplaced box would cut the
        // target itself, and each worse registration would misplace the next
        // box further; the sphere alone is safe then.
        let trusted = pred.attitude.as_ref().is_some_and(|a| {
            3.0 * a.sigma_at(scan_end_s - pred.t_s) * config.target_bounding_radius_m
                < config.margin_m
        });
        roi.oriented = config.body_box.filter(|_| trusted).and_then(|b| {
            OrientedBox::new(b.grown(config.margin_m), pred, scan_start_s, scan_end_s)
        });
        (roi, None)
    }

    /// Without a prediction, narrows the region to the target found among
    /// `points` (those of the range gate and the static box); unchanged
    /// with a prediction or when nothing is found.
    pub fn detect_in(mut self, points: &[Point], config: &IngestConfig) -> Self {
        if self.sphere.is_some() || !config.detect.enabled {
            return self;
        }
        let candidates: Vec<Point> = points
            .iter()
            .filter(|p| self.contains(p))
            .copied()
            .collect();
        self.detection = detect(
            &candidates,
            config.target_bounding_radius_m,
            config.margin_m,
            &config.detect,
        );
        self
    }

    /// Which kind of region this is.
    pub fn kind(&self) -> RoiKind {
        match (&self.sphere, &self.static_box) {
            (Some(_), _) if self.oriented.is_some() => RoiKind::PredictedWithAttitude,
            (Some(_), _) => RoiKind::Predicted,
            (None, _) if self.detection.is_some() => RoiKind::Detected,
            (None, Some(_)) => RoiKind::StaticBox,
            (None, None) => RoiKind::RangeOnly,
        }
    }

    /// The target found in the frame, when there was no prediction.
    pub fn detection(&self) -> Option<&Detection> {
        self.detection.as_ref()
    }

    /// The predicted centre of the sphere (m, sensor frame), if any.
    pub fn centre(&self) -> Option<Vector3<f64>> {
        self.sphere.map(|(c, _)| c)
    }

    /// True when the point is inside the region (a non-finite point never is).
    #[inline]
    pub fn contains(&self, p: &Point) -> bool {
        let v = p.position();
        let r2 = v.norm_squared();
        // Written so that NaN compares false and is rejected.
        let in_gate = r2 >= self.min_range2 && r2 <= self.max_range2;
        if !in_gate {
            return false;
        }
        if let Some((c, radius2)) = &self.sphere {
            if (v - c).norm_squared() > *radius2 {
                return false;
            }
            return self.oriented.as_ref().is_none_or(|o| o.contains(&v, p.t));
        }
        if self
            .static_box
            .is_some_and(|b| !b.contains([v.x, v.y, v.z]))
        {
            return false;
        }
        self.detection.as_ref().is_none_or(|d| d.contains(&v))
    }
}

#[cfg(test)]
#[path = "roi_tests.rs"]
mod tests;
