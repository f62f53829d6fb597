//! What `spacepose eval tracking` measures: a record per frame and mode,
//! scored against truth as in seed 000 Tables 2-3, and its summary.

use super::acquisition::{AcquisitionCounts, AcquisitionRecord};
use crate::stats::{MeanMax, median};
use nalgebra::Rotation3;
use serde::Serialize;
use spacepose_geometry::Pose;
use spacepose_lidar_sim::Frame;
use spacepose_messages::PoseEstimate;
use spacepose_tracker::{TrackOutput, TrackStatus};
use spacepose_tracker_node::wire::status_from_wire;
use std::collections::BTreeMap;

pub use super::bounds::{DIVERGED_DEG, DIVERGED_M};
use super::bounds::{far_off, pose_error};

/// One frame of one mode.
#[derive(Debug, Clone, Serialize)]
pub struct FrameRecord {
    /// Frame index within the scenario.
    pub frame: usize,
    /// Scan end (s).
    pub t: f64,
    /// Range to the target centre of mass (m).
    pub range_m: f64,
    /// Tracker status.
    pub status: TrackStatus,
    /// The published `t_sensor_target`: quaternion w, x, y, z (the
    /// estimate's own numbers, as the suite publishes them).
    pub q_sensor_target: [f64; 4],
    /// The published position of the target in the sensor frame (m).
    pub p_sensor_target_m: [f64; 3],
    /// Angular error (deg); NaN when lost.
    pub ang_err_deg: f64,
    /// Position error (cm); NaN when lost.
    pub pos_err_cm: f64,
    /// The attitude error as a rotation vector in the target frame,
    /// `Log(Qᵀ R)` against the truth `Q` (its symmetric variant nearest the
    /// estimate `R`), in degrees: its direction tells a twin lock (deos:
    /// about body x, 60°) from a slide. NaN when lost.
    pub err_rotvec_target_deg: [f64; 3],
    /// Error of the filter's angular velocity after this frame, `|ω̂ − ω|`
    /// in the target frame (deg/s).
    pub w_err_deg_s: f64,
    /// Its component along the true ω (deg/s; for a spinning target, the
    /// spin-rate error that drifts an unobservable roll).
    pub w_err_along_deg_s: f64,
    /// Processing time, voxel filter included (ms).
    pub time_ms: f64,
    /// Registration iterations.
    pub iterations: usize,
    /// Mean registration cost per inlier (NDT: Mahalanobis; ICP: m²).
    pub cost_mean: f64,
    /// Fraction of the used points with a correspondence.
    pub inlier_fraction: f64,
    /// Directions left at the prediction as unobservable.
    pub degenerate_directions: usize,
    /// The weakest rotation's lever arm (m; NaN when not computed).
    pub weakest_lever_arm_m: f64,
    /// Standard deviation of the held rotation (deg, `spacepose_tracker::HeldAxes`);
    /// NaN (null) when nothing was held.
    pub held_sigma_deg: f64,
    /// Translations left at the prediction as weakly constrained.
    pub held_translations: usize,
    /// The weakest translation's RMS cosine with the surface normals
    /// (`spacepose_registration::weak_directions`; NaN when not computed).
    pub weakest_translation_cosine: f64,
    /// Standard deviation of the held translation (cm); NaN (null) when
    /// none was held.
    pub held_sigma_cm: f64,
    /// Raw points in the frame.
    pub points_in: usize,
    /// Points after pre-processing.
    pub points_used: usize,
    /// Points the visibility gate dropped as lying behind the model at the
    /// prediction (`spacepose_tracker::visibility`).
    pub points_behind: usize,
    /// What ingest's crop passed on, by kind of return (the simulator's
    /// labels; null when the frame did not get through ingest).
    pub crop: Option<super::crop_score::CropKinds>,
    /// Registered again on the cloud gated at the first fit
    /// (`spacepose_tracker::VisibilityConfig::refit`).
    pub refit: bool,
    /// Attitude difference between the registration and the filter's
    /// prediction (deg; NaN without a registration).
    pub innovation_rot_deg: f64,
    /// NIS of the registration against the prediction, with the covariance
    /// the filter fuses (χ²(6) when consistent; NaN without one).
    pub nis: f64,
    /// Why the frame is degraded or lost (empty when tracking).
    pub reason: String,
    /// Scan blur: the angle the true attitude turns between the mean time
    /// of the frame's target returns and the scan end (deg). A one-pose fit
    /// of the uncompensated cloud sees the target near its mean time, so
    /// `ndt` and `icp` modes lag the end-of-scan truth by about this much
    /// even when fully converged (see [`blur_lag_deg`]). The same in every
    /// mode.
    pub blur_lag_deg: f64,
    /// `ct-ndt` mode: CT-NDT stalled and the frame was fitted as `deblur`
    /// fits it (`TrackerConfig::ct_ndt_stall_fallback`).
    pub fallback: bool,
    /// `deblur` mode: fitted by CT-NDT in the start-up
    /// (`TrackerConfig::start_up_blur_deg`).
    pub start_up: bool,
    /// NEES of the published pose against the truth with its published
    /// covariance ([`super::nees`]); NaN without a pose or a covariance.
    pub nees: f64,
    /// The filter service's posterior after this frame, against the truth
    /// (deg; [`super::filter_score`]); NaN when the frame was not fused.
    pub filter_ang_err_deg: f64,
    /// Its position error (cm).
    pub filter_pos_err_cm: f64,
    /// Its NEES with the filter's own pose covariance.
    pub filter_nees: f64,
    /// The acquisition init published on this frame, when the suite
    /// acquires (`--init acquire`); it applies from the next frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub acquisition: Option<AcquisitionRecord>,
}

/// Summary of one mode (the columns of seed 000 Tables 2-3).
#[derive(Debug, Clone, Serialize)]
pub struct ModeReport {
    /// Angular error over frames with a pose (deg).
    pub ang_err_deg: MeanMax,
    /// Position error over frames with a pose (cm).
    pub pos_err_cm: MeanMax,
    /// Execution time (ms).
    pub time_ms: MeanMax,
    /// Median execution time (ms).
    pub time_ms_median: f64,
    /// Registration iterations.
    pub iterations: MeanMax,
    /// Angular error after the warm-up frames (deg).
    pub ang_err_deg_converged: MeanMax,
    /// Position error after the warm-up frames (cm).
    pub pos_err_cm_converged: MeanMax,
    /// Frames the tracker reported lost.
    pub lost_frames: usize,
    /// Frames the tracker reported degraded.
    pub degraded_frames: usize,
    /// Frames the tracker published `unconfirmed` (the acquisition
    /// awaiting its confirmation by a second look).
    pub unconfirmed_frames: usize,
    /// Frames whose true error exceeded 10° or 50 cm (including lost ones).
    pub diverged_frames: usize,
    /// Frames fitted by the stall fallback (`ct-ndt` mode).
    pub fallback_frames: usize,
    /// Acquisitions by verdict (all zero from a truth start).
    pub acquisitions: AcquisitionCounts,
    /// Frames published `tracking` beyond the far-off bound: silent wrong
    /// poses.
    pub silent_frames: usize,
    /// Consistency of the published covariance over the frames with a pose.
    pub nees: super::nees::NeesSummary,
    /// The filter's posterior over the frames it fused: angular error (deg).
    pub filter_ang_err_deg: MeanMax,
    /// Its position error (cm).
    pub filter_pos_err_cm: MeanMax,
    /// Consistency of the filter's own covariance.
    pub filter_nees: super::nees::NeesSummary,
    /// NIS of the registrations against the predictions (the same χ²(6)
    /// bounds as the NEES).
    pub nis: super::nees::NeesSummary,
    /// Frames run.
    pub frames: usize,
    /// Per-frame records.
    pub series: Vec<FrameRecord>,
}

/// The whole evaluation.
#[derive(Debug, Clone, Serialize)]
pub struct TrackingReport {
    /// Scenario name.
    pub scenario: String,
    /// Target name.
    pub target: String,
    /// The test facility's background was in the frames.
    pub clutter: bool,
    /// The world departed from the model (`--mismatch`).
    pub mismatch: bool,
    /// Seed.
    pub seed: u64,
    /// Frames run.
    pub frames: usize,
    /// First frame index.
    pub first_frame: usize,
    /// Chaser-trajectory compression.
    pub compression: f64,
    /// Warm-up frames excluded from the converged statistics.
    pub warmup: usize,
    /// Mean raw points per frame.
    pub mean_points_in: f64,
    /// Scan blur over the frames (deg; see [`FrameRecord::blur_lag_deg`]).
    pub blur_lag_deg: MeanMax,
    /// Results per mode name.
    pub modes: BTreeMap<String, ModeReport>,
}

impl FrameRecord {
    /// More than [`DIVERGED_DEG`] or [`DIVERGED_M`] off in truth; a frame
    /// without a pose (NaN errors) counts.
    pub fn far_off(&self) -> bool {
        far_off(self.ang_err_deg, self.pos_err_cm / 100.0)
    }

    /// Published `tracking` while far off: a silent wrong pose.
    pub fn silent(&self) -> bool {
        self.status == TrackStatus::Tracking && self.far_off()
    }
}

/// Sets the filter's figures of `r` from the service's state after the frame.
pub fn score_filter(
    r: &mut FrameRecord,
    frame: &Frame,
    state: Option<&spacepose_messages::FilterState>,
    symmetries: &[Rotation3<f64>],
) {
    let f = super::filter_score::score(
        state,
        frame.scan_end,
        &frame.truth.t_sensor_target,
        symmetries,
    );
    r.filter_ang_err_deg = f.ang_err_deg;
    r.filter_pos_err_cm = f.pos_err_cm;
    r.filter_nees = f.nees;
}

/// The record of frame `index`: the estimate the tracker published, scored
/// against the frame's truth, with the registration's figures from its
/// `TrackOutput` (absent when the cloud never reached the tracker).
/// `blur_lag_deg` is left NaN for the caller to set.
///
/// `symmetries` is the target's group when the track may have started from
/// a symmetric twin (an acquisition): the attitude error is then d_sym.
/// Empty from a truth start, where a flip to a twin counts as an error.
pub fn record(
    frame: &Frame,
    index: usize,
    estimate: &PoseEstimate,
    out: Option<&TrackOutput>,
    symmetries: &[Rotation3<f64>],
) -> FrameRecord {
    // An unknown code reads `lost`.
    let status = estimate
        .wire_status()
        .map_or(TrackStatus::Lost, status_from_wire);
    let pose = estimate.pose().ok().filter(|_| status != TrackStatus::Lost);
    let truth = &frame.truth;
    let (ang, pos) = pose.map_or((f64::NAN, f64::NAN), |p: Pose| {
        let (a, d) = pose_error(&p, &truth.t_sensor_target, symmetries);
        (a, d * 100.0)
    });
    let err_rotvec_target_deg = pose.map_or([f64::NAN; 3], |p: Pose| {
        let v = super::bounds::error_rotvec(&p, &truth.t_sensor_target, symmetries);
        [v.x.to_degrees(), v.y.to_degrees(), v.z.to_degrees()]
    });
    let nees = pose
        .and_then(|p| {
            super::nees::pose_nees(&p, &estimate.covariance, &truth.t_sensor_target, symmetries)
        })
        .unwrap_or(f64::NAN);
    let w = out.map_or(nalgebra::Vector3::repeat(f64::NAN), |o| o.w_target);
    let w_err = w - truth.w_target;
    let along = truth.w_target.try_normalize(1e-12).unwrap_or_default();
    let reg = out.and_then(|o| o.registration.as_ref());
    FrameRecord {
        frame: index,
        t: frame.scan_end,
        range_m: truth.t_sensor_target.translation.norm(),
        status,
        q_sensor_target: estimate.q_sensor_target,
        p_sensor_target_m: estimate.p_sensor_target,
        ang_err_deg: ang,
        pos_err_cm: pos,
        err_rotvec_target_deg,
        w_err_deg_s: w_err.norm().to_degrees(),
        w_err_along_deg_s: w_err.dot(&along).to_degrees(),
        time_ms: out.map_or(f64::NAN, |o| o.timings.total_ms),
        iterations: out.map_or(0, TrackOutput::iterations),
        cost_mean: reg.map_or(f64::NAN, |r| r.cost.mean),
        inlier_fraction: reg.map_or(f64::NAN, |r| r.inlier_fraction()),
        degenerate_directions: reg.map_or(0, |r| r.degenerate_directions),
        weakest_lever_arm_m: reg.map_or(f64::NAN, |r| r.weakest_lever_arm_m),
        held_sigma_deg: out
            .and_then(|o| o.held.as_ref())
            .filter(|h| h.count > 0)
            .map_or(f64::NAN, |h| h.sigma_rad.to_degrees()),
        held_translations: reg.map_or(0, |r| r.held_translations),
        weakest_translation_cosine: reg.map_or(f64::NAN, |r| r.weakest_translation_cosine),
        held_sigma_cm: out
            .and_then(|o| o.held.as_ref())
            .filter(|h| h.translations > 0)
            .map_or(f64::NAN, |h| h.sigma_m * 100.0),
        points_in: frame.points.len(),
        points_used: out.map_or(0, |o| o.points_used),
        points_behind: out.map_or(0, |o| o.points_behind),
        crop: None,
        refit: out.is_some_and(|o| o.refit),
        innovation_rot_deg: out.map_or(f64::NAN, |o| o.innovation_rot_deg),
        nis: out.map_or(f64::NAN, |o| o.nis),
        reason: out.map_or_else(String::new, |o| o.reason.clone()),
        blur_lag_deg: f64::NAN,
        fallback: out.is_some_and(|o| o.fallback),
        start_up: out.is_some_and(|o| o.start_up),
        nees,
        filter_ang_err_deg: f64::NAN,
        filter_pos_err_cm: f64::NAN,
        filter_nees: f64::NAN,
        acquisition: None,
    }
}

/// The summary of one mode's per-frame records, `warmup` frames excluded
/// from the converged statistics.
pub fn summarise(series: Vec<FrameRecord>, warmup: usize) -> ModeReport {
    let pick = |f: fn(&FrameRecord) -> f64, skip: usize| -> Vec<f64> {
        series.iter().skip(skip).map(f).collect()
    };
    let count = |s: TrackStatus| series.iter().filter(|r| r.status == s).count();
    let diverged = series.iter().filter(|r| r.far_off()).count();
    let times = pick(|r| r.time_ms, 0);
    ModeReport {
        ang_err_deg: MeanMax::of(&pick(|r| r.ang_err_deg, 0)),
        pos_err_cm: MeanMax::of(&pick(|r| r.pos_err_cm, 0)),
        time_ms: MeanMax::of(&times),
        time_ms_median: median(&times),
        iterations: MeanMax::of(&pick(|r| r.iterations as f64, 0)),
        ang_err_deg_converged: MeanMax::of(&pick(|r| r.ang_err_deg, warmup)),
        pos_err_cm_converged: MeanMax::of(&pick(|r| r.pos_err_cm, warmup)),
        lost_frames: count(TrackStatus::Lost),
        degraded_frames: count(TrackStatus::Degraded),
        unconfirmed_frames: count(TrackStatus::Unconfirmed),
        diverged_frames: diverged,
        fallback_frames: series.iter().filter(|r| r.fallback).count(),
        acquisitions: AcquisitionCounts::of(series.iter().filter_map(|r| r.acquisition.as_ref())),
        silent_frames: series.iter().filter(|r| r.silent()).count(),
        nees: super::nees::NeesSummary::of(series.iter().map(|r| r.nees)),
        filter_ang_err_deg: MeanMax::of(&pick(|r| r.filter_ang_err_deg, 0)),
        filter_pos_err_cm: MeanMax::of(&pick(|r| r.filter_pos_err_cm, 0)),
        filter_nees: super::nees::NeesSummary::of(series.iter().map(|r| r.filter_nees)),
        nis: super::nees::NeesSummary::of(series.iter().map(|r| r.nis)),
        frames: series.len(),
        series,
    }
}
