//! Scoring a run: poses against truth, frame by frame, and the summary.

use super::chaos::ChaosReport;
use crate::suite::swap::SwapReport;
use nalgebra::Rotation3;
use serde::Serialize;
use spacepose_eval::stats::{MeanMax, median};
use spacepose_geometry::so3;
use spacepose_messages::{
    FilterState, PoseEstimate, TruthMsg, WireStatus, elapsed_ms, mode_from_code,
};
use std::collections::{BTreeMap, HashMap};

/// One scored frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameScore {
    /// Frame sequence.
    pub sequence: u64,
    /// Track status of the pose.
    pub status: String,
    /// Angle between estimated and true rotation (deg): `d_sym` of seed 004
    /// Eq. (14) over the target's symmetry group (plain `d` without one).
    pub ang_err_deg: f64,
    /// Distance between estimated and true position (cm).
    pub pos_err_cm: f64,
    /// Tracker compute time (ms).
    pub tracker_ms: f64,
    /// Registration iterations.
    pub iterations: u32,
    /// Raw cloud published by the sensor → pose published (ms); NaN if the
    /// raw cloud was not seen.
    pub latency_ms: f64,
    /// Cropped cloud published by ingest → pose published (ms).
    pub tracker_latency_ms: f64,
    /// `latency_ms - tracker_ms`: what the pipeline adds to the computation (ms).
    pub overhead_ms: f64,
}

/// Collects poses, truths and raw-cloud publish times by sequence.
#[derive(Debug, Default)]
pub struct Scorer {
    truth: BTreeMap<u64, TruthMsg>,
    poses: BTreeMap<u64, PoseEstimate>,
    raw_published_ns: BTreeMap<u64, i64>,
    scored: BTreeMap<u64, FrameScore>,
    /// Poses that arrived for an already scored frame (a second tracker).
    pub duplicate_poses: u64,
    /// Poses that could not be scored (bad quaternion...).
    pub unscorable: u64,
    mode: Option<String>,
    /// First pose of each frame: (time of validity, cloud published ns, tracking).
    frames: BTreeMap<u64, (f64, i64, bool)>,
    /// First filter state published at each time of validity (bits of t_s).
    fused_ns: HashMap<u64, i64>,
    /// Symmetry group of the target (empty: none), for `d_sym`.
    symmetries: Vec<Rotation3<f64>>,
}

impl Scorer {
    /// A scorer for a target with this symmetry group.
    ///
    /// An acquisition (CNN or template matching) finds the pose of a
    /// symmetric target only up to its symmetry group (seed 004 §III.C.4):
    /// the tracker then follows an equivalent pose, and the demo scores it
    /// with `d_sym`. A flip *during* tracking to another member of the group
    /// is still visible as a jump in the pose stream, but it is no longer an
    /// error against the truth. (`eval tracking` starts from the truth and
    /// keeps the strict `d`.)
    pub fn with_symmetries(symmetries: Vec<Rotation3<f64>>) -> Self {
        Self {
            symmetries,
            ..Self::default()
        }
    }

    /// Records a truth message; returns the frames that became scorable.
    pub fn on_truth(&mut self, t: TruthMsg) -> Vec<FrameScore> {
        self.truth.insert(t.sequence, t);
        self.try_score(t.sequence)
    }

    /// Records a pose; returns the frames that became scorable.
    pub fn on_pose(&mut self, p: PoseEstimate) -> Vec<FrameScore> {
        let tracking = WireStatus::from_u8(p.status).is_ok_and(WireStatus::is_tracked);
        self.frames
            .entry(p.sequence)
            .or_insert((p.t_s, p.cloud_published_ns, tracking));
        if self.poses.contains_key(&p.sequence) || self.scored.contains_key(&p.sequence) {
            self.duplicate_poses += 1;
            return Vec::new();
        }
        if self.mode.is_none() {
            self.mode = mode_from_code(p.mode).ok().map(|m| m.as_str().to_string());
        }
        self.poses.insert(p.sequence, p);
        self.try_score(p.sequence)
    }

    /// Records a filter state (its time of validity is the fused frame's).
    pub fn on_state(&mut self, s: &FilterState) {
        if s.initialized != 0 {
            self.fused_ns
                .entry(s.t_s.to_bits())
                .or_insert(s.published_ns);
        }
    }

    /// Per frame with a pose: (sequence, cloud published ns, fused state
    /// published ns if a state at its time was seen).
    pub fn fusions(&self) -> Vec<(u64, i64, Option<i64>)> {
        self.frames
            .iter()
            .map(|(seq, (t, cloud, _))| (*seq, *cloud, self.fused_ns.get(&t.to_bits()).copied()))
            .collect()
    }

    /// Frames whose first pose was `tracking` (or `unconfirmed`: fused too) but no filter state at its
    /// time was seen (no estimate of the frame was fused).
    pub fn unfused_tracking_frames(&self) -> u64 {
        self.frames
            .values()
            .filter(|(t, _, tracking)| *tracking && !self.fused_ns.contains_key(&t.to_bits()))
            .count() as u64
    }

    /// Records when a raw frame was published (ns, CLOCK_REALTIME).
    pub fn on_raw_cloud(&mut self, sequence: u64, published_ns: i64) {
        self.raw_published_ns.insert(sequence, published_ns);
    }

    fn try_score(&mut self, sequence: u64) -> Vec<FrameScore> {
        let (Some(p), Some(t)) = (self.poses.get(&sequence), self.truth.get(&sequence)) else {
            return Vec::new();
        };
        let Some(score) = score(
            p,
            t,
            self.raw_published_ns.get(&sequence).copied(),
            &self.symmetries,
        ) else {
            self.unscorable += 1;
            self.poses.remove(&sequence);
            return Vec::new();
        };
        self.poses.remove(&sequence);
        self.scored.insert(sequence, score.clone());
        vec![score]
    }

    /// Truth messages received (frames the sensor produced).
    pub fn truths(&self) -> usize {
        self.truth.len()
    }

    /// The newest frame the sensor produced (a restarted sensor skips the
    /// frames due while it was dead, so this can be ahead of `truths`).
    pub fn newest_truth(&self) -> Option<u64> {
        self.truth.keys().next_back().copied()
    }

    /// Frames with a scored pose.
    pub fn scored(&self) -> &BTreeMap<u64, FrameScore> {
        &self.scored
    }

    /// Poses waiting for their truth.
    pub fn pending_poses(&self) -> usize {
        self.poses.len()
    }

    /// Tracking mode of the first pose.
    pub fn mode(&self) -> Option<&str> {
        self.mode.as_deref()
    }
}

/// Scores one pose against the truth of the same frame.
pub fn score(
    p: &PoseEstimate,
    t: &TruthMsg,
    raw_published_ns: Option<i64>,
    symmetries: &[Rotation3<f64>],
) -> Option<FrameScore> {
    let (estimate, truth) = (p.pose().ok()?, t.pose().ok()?);
    let angle_rad = so3::distance_sym(&estimate.rotation, &truth.rotation, symmetries);
    let dist_m = (estimate.translation - truth.translation).norm();
    let status = WireStatus::from_u8(p.status).map_or("?", WireStatus::as_str);
    let latency_ms = raw_published_ns
        .and_then(|ns| elapsed_ms(ns, p.published_ns))
        .unwrap_or(f64::NAN);
    Some(FrameScore {
        sequence: p.sequence,
        status: status.to_string(),
        ang_err_deg: angle_rad.to_degrees(),
        pos_err_cm: dist_m * 100.0,
        tracker_ms: p.total_ms,
        iterations: p.iterations,
        latency_ms,
        tracker_latency_ms: elapsed_ms(p.cloud_published_ns, p.published_ns).unwrap_or(f64::NAN),
        overhead_ms: latency_ms - p.total_ms,
    })
}

/// Mean, median and max.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Spread {
    /// Mean.
    pub mean: f64,
    /// Median.
    pub median: f64,
    /// Maximum.
    pub max: f64,
}

impl Spread {
    /// Of the finite values of `v` (NaN when none).
    pub fn of(v: &[f64]) -> Self {
        let mm = MeanMax::of(v);
        Self {
            mean: mm.mean,
            median: median(v),
            max: mm.max,
        }
    }
}

/// The fusion latency of one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FusionTime {
    /// Frame sequence.
    pub sequence: u64,
    /// When ingest published its cloud (ns, CLOCK_REALTIME).
    pub cloud_published_ns: i64,
    /// Cloud published by ingest → filter state published (ms).
    pub latency_ms: Option<f64>,
}

/// The summary of a run (the `--json` file).
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// Deployment prefix of the run.
    pub prefix: String,
    /// Tracking mode.
    pub mode: String,
    /// Frames requested from the sensor.
    pub frames: u64,
    /// Frames the sensor published (truth messages received).
    pub frames_published: usize,
    /// Frames with a pose.
    pub poses_published: usize,
    /// `frames - poses_published`.
    pub missed_poses: u64,
    /// Frames excluded from the `_converged` figures (filter warm-up).
    pub warmup: usize,
    /// Angular error (deg), every frame with a measurement (not `lost`).
    pub ang_err_deg: MeanMax,
    /// Position error (cm), every frame with a measurement (not `lost`).
    pub pos_err_cm: MeanMax,
    /// Angular error after the warm-up (deg).
    pub ang_err_deg_converged: MeanMax,
    /// Position error after the warm-up (cm).
    pub pos_err_cm_converged: MeanMax,
    /// Tracker compute time (ms).
    pub tracker_ms: MeanMax,
    /// Registration iterations.
    pub iterations: MeanMax,
    /// Sensor publish → pose publish (ms).
    pub latency_ms: Spread,
    /// Ingest publish → pose publish (ms).
    pub tracker_latency_ms: Spread,
    /// Latency minus tracker compute (ms): the pipeline overhead.
    pub overhead_ms: Spread,
    /// Frames per status (`tracking`, `degraded`, `lost`).
    pub status_counts: BTreeMap<String, usize>,
    /// Frames tracked (first pose `tracking`) for which the filter published
    /// no state at their time: no estimate of theirs was fused.
    pub unfused_tracking_frames: u64,
    /// Cloud published by ingest → filter state of that frame published
    /// (ms): includes the wait for the primary up to the frame deadline.
    pub fusion_latency_ms: Spread,
    /// Per frame with a pose: cloud published by ingest → filter state of
    /// that frame published (ms; null when no state at its time was seen).
    pub fusions: Vec<FusionTime>,
    /// Injected faults and what the supervisor did (`--chaos`).
    pub chaos: Vec<ChaosReport>,
    /// The run-time swap (`--swap`).
    pub swap: Option<SwapReport>,
    /// Restarts per instance by the supervisor.
    pub restarts: BTreeMap<String, u32>,
    /// Per-frame scores.
    pub series: Vec<FrameScore>,
}

impl Summary {
    /// Summarises `scorer` for a run of `frames` frames.
    pub fn new(prefix: &str, scorer: &Scorer, frames: u64, warmup: usize) -> Self {
        let series: Vec<FrameScore> = scorer.scored().values().cloned().collect();
        let col = |f: fn(&FrameScore) -> f64, skip: usize| -> Vec<f64> {
            series
                .iter()
                .filter(|s| s.sequence >= skip as u64)
                .map(f)
                .collect()
        };
        // Errors are taken over frames with a measurement: a `lost` pose is
        // the prediction (or nothing, before the first acquisition) and is
        // counted in `status_counts` instead.
        let err = |f: fn(&FrameScore) -> f64, skip: usize| -> Vec<f64> {
            series
                .iter()
                .filter(|s| s.sequence >= skip as u64 && s.status != "lost")
                .map(f)
                .collect()
        };
        let first = series.first().map_or(0, |s| s.sequence as usize);
        let mut status_counts = BTreeMap::new();
        for s in &series {
            *status_counts.entry(s.status.clone()).or_insert(0) += 1;
        }
        Self {
            prefix: prefix.to_string(),
            mode: scorer.mode().unwrap_or("?").to_string(),
            frames,
            frames_published: scorer.truths(),
            poses_published: series.len(),
            missed_poses: frames.saturating_sub(series.len() as u64),
            warmup,
            ang_err_deg: MeanMax::of(&err(|s| s.ang_err_deg, 0)),
            pos_err_cm: MeanMax::of(&err(|s| s.pos_err_cm, 0)),
            ang_err_deg_converged: MeanMax::of(&err(|s| s.ang_err_deg, first + warmup)),
            pos_err_cm_converged: MeanMax::of(&err(|s| s.pos_err_cm, first + warmup)),
            tracker_ms: MeanMax::of(&col(|s| s.tracker_ms, 0)),
            iterations: MeanMax::of(&col(|s| f64::from(s.iterations), 0)),
            latency_ms: Spread::of(&col(|s| s.latency_ms, 0)),
            tracker_latency_ms: Spread::of(&col(|s| s.tracker_latency_ms, 0)),
            overhead_ms: Spread::of(&col(|s| s.overhead_ms, 0)),
            status_counts,
            unfused_tracking_frames: scorer.unfused_tracking_frames(),
            fusion_latency_ms: Spread::of(
                &scorer
                    .fusions()
                    .iter()
                    .filter_map(|(_, cloud, fused)| fused.map(|f| (f - cloud) as f64 * 1e-6))
                    .collect::<Vec<_>>(),
            ),
            fusions: scorer
                .fusions()
                .iter()
                .map(|(sequence, cloud, fused)| FusionTime {
                    sequence: *sequence,
                    cloud_published_ns: *cloud,
                    latency_ms: fused.map(|f| (f - cloud) as f64 * 1e-6),
                })
                .collect(),
            chaos: Vec::new(),
            swap: None,
            restarts: BTreeMap::new(),
            series,
        }
    }
}

#[cfg(test)]
#[path = "score_tests.rs"]
mod tests;
