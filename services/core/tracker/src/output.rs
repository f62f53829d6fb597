//! What the tracker returns for every frame.

use crate::held_axes::HeldAxes;
use crate::status::TrackStatus;
use nalgebra::{Matrix6, Vector3};
use spacepose_filter::Prediction;
use spacepose_geometry::Pose;
use spacepose_registration::Registration;
use std::time::Instant;

/// Wall-clock time spent on a frame (ms, one thread).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Timings {
    /// Motion compensation and voxel filter.
    pub preprocess_ms: f64,
    /// Registration.
    pub registration_ms: f64,
    /// Whole frame: pre-processing, registration and filter update. This is
    /// the "execution time" of seed 000 Tables 2-3 (voxel filter included).
    pub total_ms: f64,
}

/// The tracker's answer for one frame.
#[derive(Debug, Clone)]
pub struct TrackOutput {
    /// Scan end time: the time the pose refers to (s).
    pub t: f64,
    /// Estimated `t_sensor_target` at scan end. For a lost frame, and for a
    /// degraded one in `deblur` and `ct-ndt` modes, the filter prediction
    /// (flagged by `status`; the doubted measurement is in `registration`).
    pub t_sensor_target: Pose,
    /// Covariance of `t_sensor_target` (left ⊕, `[rot; trans]`): from the
    /// registration information, or the prediction's where the pose is the
    /// prediction; `None` when degenerate or lost.
    pub covariance: Option<Matrix6<f64>>,
    /// Track health after this frame.
    pub status: TrackStatus,
    /// Why the frame is degraded or lost (empty when tracking).
    pub reason: String,
    /// The registration's full result, when it ran to completion.
    pub registration: Option<Registration>,
    /// Attitude difference between the measurement and the filter
    /// prediction (deg); NaN without a measurement.
    pub innovation_rot_deg: f64,
    /// Position difference between the measurement and the prediction (m).
    pub innovation_pos_m: f64,
    /// Normalised innovation squared of the measurement against the
    /// prediction, with the covariance the filter fuses (χ²(6) when both
    /// are consistent); NaN without a measurement.
    pub nis: f64,
    /// Filter's angular velocity after the frame, target frame (rad/s).
    pub w_target: Vector3<f64>,
    /// Filter's velocity after the frame, sensor frame (m/s).
    pub v_sensor: Vector3<f64>,
    /// Points received.
    pub points_in: usize,
    /// Points after pre-processing (what the registration saw).
    pub points_used: usize,
    /// Time spent.
    pub timings: Timings,
    /// `ct-ndt` mode: CT-NDT stalled (no convergence, still moving at its
    /// iteration limit), and this pose is the one-pose fit of the cloud
    /// motion-compensated by the prediction, as `deblur` computes it
    /// ([`crate::TrackerConfig::ct_ndt_stall_fallback`]).
    pub fallback: bool,
    /// `deblur` mode: fitted as `ct-ndt` fits it, the filter's angular rate
    /// being still too uncertain to compensate the scan
    /// ([`crate::TrackerConfig::start_up_blur_deg`]).
    pub start_up: bool,
    /// Points the visibility gate found behind the model at the prediction
    /// and dropped (`crate::visibility`): mirror ghosts of reflections.
    pub points_behind: usize,
    /// The frame was registered again on the cloud gated at the first fit
    /// ([`crate::VisibilityConfig::refit`]); `points_behind` then adds the
    /// second gate's count.
    pub refit: bool,
    /// The rotations the registration held and their uncertainty
    /// ([`crate::held_axes`]); `None` when it held none or did not run.
    pub held: Option<HeldAxes>,
}

impl TrackOutput {
    /// A `lost` frame without a measurement: the filter's `prediction`,
    /// no covariance, `reason`, and the time since `started`.
    pub fn lost(prediction: &Prediction, points_in: usize, reason: &str, started: Instant) -> Self {
        TrackOutput {
            t: prediction.t,
            t_sensor_target: prediction.pose,
            covariance: None,
            status: TrackStatus::Lost,
            reason: reason.to_string(),
            registration: None,
            innovation_rot_deg: f64::NAN,
            innovation_pos_m: f64::NAN,
            nis: f64::NAN,
            w_target: prediction.w_target,
            v_sensor: prediction.v_sensor,
            points_in,
            points_used: 0,
            timings: Timings {
                total_ms: started.elapsed().as_secs_f64() * 1e3,
                ..Timings::default()
            },
            fallback: false,
            start_up: false,
            points_behind: 0,
            refit: false,
            held: None,
        }
    }

    /// False when the frame carried no measurement (too few points to
    /// register, or the registration failed): the pose is then the filter
    /// prediction, the status `lost`, and nothing was fused.
    pub fn has_measurement(&self) -> bool {
        self.registration.is_some()
    }

    /// Rotations held by the registration (0 when none, or none ran).
    pub fn held_axes(&self) -> usize {
        self.held.as_ref().map_or(0, |h| h.count)
    }

    /// Translations held by the registration (0 when none, or none ran).
    pub fn held_translations(&self) -> usize {
        self.held.as_ref().map_or(0, |h| h.translations)
    }

    /// Registration iterations (0 when none ran).
    pub fn iterations(&self) -> usize {
        self.registration.as_ref().map_or(0, |r| r.iterations)
    }
}
