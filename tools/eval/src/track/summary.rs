//! What `spacepose track` tells at the end: frame counts by status, every
//! acquisition, timings and, when the recording has truth, the errors.
//!
//! Scoring uses the eval's one error and far-off bound
//! ([`crate::tracking::bounds`]): a frame published `tracking` that
//! far from the truth is a silent wrong pose, and an accepted acquisition
//! that far is a false accept (the tracker starts from it). Attitudes are
//! compared with d_sym over the target's symmetries: an acquisition may
//! start the track on a symmetric twin.

use super::truth::TruthPoses;
use crate::stats::MeanMax;
use crate::tracking::acquisition::{self, AcquisitionCounts, AcquisitionRecord};
use crate::tracking::bounds::{far_off, pose_error};
use nalgebra::Rotation3;
use serde::Serialize;
use spacepose_geometry::Pose;
use spacepose_messages::{AcquisitionResult, PoseEstimate};

/// The run's summary.
#[derive(Debug, Clone, Default, Serialize)]
pub struct TrackSummary {
    /// Frames read and tracked.
    pub frames: usize,
    /// Frames the recording could not give (unreadable, corrupt), skipped.
    pub frames_skipped: usize,
    /// Frames whose point times were derived (no time field).
    pub frames_derived_times: usize,
    /// Frames published `tracking`, `degraded`, `lost`, `unconfirmed`.
    pub tracking: usize,
    /// See `tracking`.
    pub degraded: usize,
    /// See `tracking`.
    pub lost: usize,
    /// See `tracking` (tracked, the acquisition not yet verified).
    pub unconfirmed: usize,
    /// Every acquisition, in order.
    pub acquisitions: Vec<AcquisitionRecord>,
    /// The acquisitions by verdict.
    pub acquisition_counts: AcquisitionCounts,
    /// Tracker time per frame (ms).
    pub time_ms: MeanMax,
    /// Errors of the frames with a pose (not `lost`), when the recording
    /// has truth.
    pub errors: Option<Errors>,
}

/// Errors against the truth.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Errors {
    /// Frames scored (published with a pose, not `lost`; truth known).
    pub frames_scored: usize,
    /// Attitude error (deg, d_sym over the target's symmetry group).
    pub ang_err_deg: MeanMax,
    /// Position error (cm).
    pub pos_err_cm: MeanMax,
    /// Frames published `tracking` beyond the far-off bound: silent wrong poses.
    pub silent_far_off: usize,
}

/// Collects the summary frame by frame.
pub struct Scorer<'a> {
    truth: Option<&'a TruthPoses>,
    symmetries: &'a [Rotation3<f64>],
    summary: TrackSummary,
    times: Vec<f64>,
    ang: Vec<f64>,
    pos: Vec<f64>,
}

impl<'a> Scorer<'a> {
    /// Scores against `truth` (if any) with the target's `symmetries`.
    pub fn new(truth: Option<&'a TruthPoses>, symmetries: &'a [Rotation3<f64>]) -> Self {
        Scorer {
            truth,
            symmetries,
            summary: TrackSummary::default(),
            times: Vec::new(),
            ang: Vec::new(),
            pos: Vec::new(),
        }
    }

    /// The summary so far (counters of the reader are set by the caller).
    pub fn summary_mut(&mut self) -> &mut TrackSummary {
        &mut self.summary
    }

    fn error(&self, frame: u64, pose: &Pose) -> Option<(f64, f64)> {
        let truth = self.truth?.get(&frame)?;
        Some(pose_error(pose, truth, self.symmetries))
    }

    /// One frame's estimate.
    pub fn frame(&mut self, frame: u64, estimate: &PoseEstimate, status: &str) {
        self.summary.frames += 1;
        self.times.push(estimate.total_ms);
        match status {
            "tracking" => self.summary.tracking += 1,
            "degraded" => self.summary.degraded += 1,
            "unconfirmed" => self.summary.unconfirmed += 1,
            _ => {
                self.summary.lost += 1;
                return;
            }
        }
        let Some((ang, pos)) = estimate.pose().ok().and_then(|p| self.error(frame, &p)) else {
            return;
        };
        self.ang.push(ang);
        self.pos.push(pos * 100.0);
        let errors = self.summary.errors.get_or_insert_with(Errors::default);
        errors.frames_scored += 1;
        if status == "tracking" && far_off(ang, pos) {
            errors.silent_far_off += 1;
        }
    }

    /// One acquisition, computed on `frame`.
    pub fn acquisition(&mut self, frame: u64, a: &AcquisitionResult) {
        let truth = self.truth.and_then(|t| t.get(&frame));
        let record = acquisition::score(frame, a, truth, self.symmetries);
        self.summary.acquisitions.push(record);
    }

    /// The summary.
    pub fn finish(mut self) -> TrackSummary {
        self.summary.time_ms = MeanMax::of(&self.times);
        self.summary.acquisition_counts = AcquisitionCounts::of(&self.summary.acquisitions);
        if let Some(e) = self.summary.errors.as_mut() {
            e.ang_err_deg = MeanMax::of(&self.ang);
            e.pos_err_cm = MeanMax::of(&self.pos);
        }
        self.summary
    }
}

impl TrackSummary {
    /// The lines printed at the end.
    pub fn render(&self) -> String {
        let mut s = format!(
            "{} frames: {} tracking, {} unconfirmed, {} degraded, {} lost; tracker {:.1} ms mean, {:.1} ms max\n",
            self.frames,
            self.tracking,
            self.unconfirmed,
            self.degraded,
            self.lost,
            self.time_ms.mean,
            self.time_ms.max
        );
        if self.frames_skipped > 0 {
            s += &format!(
                "{} frames could not be read and were skipped\n",
                self.frames_skipped
            );
        }
        if self.frames_derived_times > 0 {
            s += &format!(
                "{} frames had no point times: derived from the scan interval and point order\n",
                self.frames_derived_times
            );
        }
        for a in &self.acquisitions {
            let err = match (a.ang_err_deg, a.pos_err_m) {
                (Some(ang), Some(pos)) => format!(", {ang:.2}° / {:.1} cm from truth", pos * 100.0),
                _ => String::new(),
            };
            s += &format!(
                "acquisition on frame {} by {}: {} (f_CONV {:.2e} m², {:.0} ms{err})\n",
                a.frame, a.method, a.verdict, a.f_conv_m2, a.time_ms
            );
        }
        if let Some(e) = &self.errors {
            s += &format!(
                "against truth ({} frames): {:.2}° mean, {:.2}° max; {:.1} cm mean, {:.1} cm max; {} silent far-off frames\n",
                e.frames_scored,
                e.ang_err_deg.mean,
                e.ang_err_deg.max,
                e.pos_err_cm.mean,
                e.pos_err_cm.max,
                e.silent_far_off
            );
        }
        s
    }
}
