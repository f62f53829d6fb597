//! The track's life cycle, without any bus: when the [`Tracker`] starts
//! (an acquisition, a reinit command, the filter service's state for a
//! fresh instance), when it follows the filter service, and what it answers
//! for each frame.
//!
//! Initialisations are applied at the next usable frame, so that the frame
//! they belong to is tracked from them.
//!
//! **Late acquisitions are caught up.** Template matching can take longer
//! than a frame period (0.2-0.9 s on one core, against 1 s frames, or
//! 0.2 s when the demo runs five times faster than real time). An
//! acquisition of frame k that arrives after frame k + 2 would start the
//! track 20° off on a 10°/s tumble, with zero rates, and registration does
//! not converge from there. So while the track waits for an acquisition,
//! the usable points of the last [`CATCH_UP_FRAMES`] frames are kept; an
//! acquisition whose time lies before some of them is applied to the first
//! of those, and they are tracked in order (their estimates were already
//! published as `lost` and are not sent again) before the frame at hand.
//! Each step then starts one frame period from its pose, as an on-time
//! acquisition does. Decision: replay rather than extrapolate, because an
//! acquisition carries no rate.

use crate::frame::FrameResult;
use crate::wire::fill_estimate;
use spacepose_filter::Prediction;
use spacepose_geometry::{Point, Pose};
use spacepose_messages::CloudHeader;
use spacepose_messages::convert::filter::zero_rates;
use spacepose_tracker::{
    TrackError, TrackOutput, TrackStatus, Tracker, TrackerConfig, TrackingMode, TrackingModel,
};
use std::collections::VecDeque;

/// Frames kept while waiting for an acquisition (see the module
/// documentation): 10 s of sensor time at 1 Hz.
pub const CATCH_UP_FRAMES: usize = 10;

/// An initialisation applied at the next usable frame.
#[derive(Debug, Clone, Copy)]
struct PendingInit {
    /// Time of validity of the pose; `None` = the next frame's scan start.
    t: Option<f64>,
    pose: Pose,
}

/// A [`Tracker`] and when it starts.
pub struct Track {
    tracker: Tracker,
    model: TrackingModel,
    pending: Option<PendingInit>,
    initialized: bool,
    /// A fresh instance (started or restarted while the suite runs, or
    /// swapped in) may start from the filter service's state; false once
    /// initialised or told to wait for an acquisition.
    warm_start: bool,
    /// The filter service's latest state, applied before the first frame
    /// that starts at or after its time: with redundant trackers a faster
    /// one's frame is often fused (and its state received) before this
    /// tracker has processed the same frame, and restoring a state from the
    /// end of the scan about to be tracked would put the filter after it.
    pending_state: Option<Prediction>,
    /// The last frames seen while not tracking, to catch up a late
    /// acquisition.
    recent: VecDeque<(CloudHeader, Vec<Point>)>,
}

impl Track {
    /// A track on `model`, not initialised.
    pub fn new(config: TrackerConfig, model: TrackingModel) -> Result<Self, TrackError> {
        Ok(Track {
            tracker: Tracker::new(config, model.clone())?,
            model,
            pending: None,
            initialized: false,
            warm_start: true,
            pending_state: None,
            recent: VecDeque::new(),
        })
    }

    /// The tracker.
    pub fn tracker(&self) -> &Tracker {
        &self.tracker
    }

    /// True when initialised and not lost.
    pub fn is_tracking(&self) -> bool {
        self.initialized && self.tracker.is_tracking()
    }

    /// Restarts the track at the next frame from `pose` at `t` (an
    /// accepted acquisition; rates unknown: zeros, seed 000 §5.2).
    pub fn start_at(&mut self, t: f64, pose: Pose) {
        self.pending = Some(PendingInit { t: Some(t), pose });
    }

    /// Restarts the track at the next frame from `pose`, placed at that
    /// frame's scan start (a reinit command with a pose).
    pub fn start_from(&mut self, pose: Pose) {
        self.pending = Some(PendingInit { t: None, pose });
    }

    /// Drops the track: the next accepted acquisition restarts it (a reinit
    /// command without a pose). The mode is kept.
    pub fn drop_track(&mut self) -> Result<(), TrackError> {
        let config = self.tracker.config().clone();
        self.tracker = Tracker::new(config, self.model.clone())?;
        self.initialized = false;
        self.warm_start = false;
        self.pending = None;
        self.pending_state = None;
        Ok(())
    }

    /// Changes the mode between two frames.
    pub fn set_mode(&mut self, mode: TrackingMode) -> Result<(), TrackError> {
        self.tracker.set_mode(mode)
    }

    /// Keeps the filter service's state to replace the local filter with
    /// before the next frame that starts at or after it (ignored while an
    /// initialisation is pending; states older than the local one are
    /// ignored when applied). A fresh instance that was never initialised
    /// starts from it (warm start of a restarted or swapped-in tracker,
    /// issue 7).
    pub fn follow(&mut self, p: Prediction) {
        if self.pending.is_none()
            && (self.initialized || self.warm_start)
            && self.pending_state.is_none_or(|old| old.t <= p.t)
        {
            self.pending_state = Some(p);
        }
    }

    /// Applies the kept filter state when it is not after the scan start.
    pub(crate) fn apply_filter_state(&mut self, header: &CloudHeader) -> Result<(), TrackError> {
        let Some(p) = self.pending_state else {
            return Ok(());
        };
        if p.t > header.scan_start_s || self.pending.is_some() {
            return Ok(());
        }
        self.pending_state = None;
        if self.initialized {
            return self.tracker.restore_filter(&p);
        }
        if self.warm_start {
            self.tracker
                .initialize(p.t, &p.pose, p.v_sensor, p.w_target)?;
            self.tracker.restore_filter(&p)?;
            self.initialized = true;
            self.warm_start = false;
        }
        Ok(())
    }

    /// Tracks the usable `points` of the frame of `header` and fills
    /// `result` (its estimate starts `lost`); returns the tracker's output
    /// when the frame reached the tracker. A late acquisition is caught up
    /// first (see the module documentation).
    pub fn track(
        &mut self,
        header: &CloudHeader,
        points: &[Point],
        result: &mut FrameResult,
    ) -> Option<TrackOutput> {
        self.catch_up(header);
        let out = self.track_one(header, points, result);
        if self.is_tracking() {
            self.recent.clear();
        } else {
            if self.recent.len() == CATCH_UP_FRAMES {
                self.recent.pop_front();
            }
            self.recent.push_back((*header, points.to_vec()));
        }
        out
    }

    /// Frames kept for a late acquisition.
    pub fn kept_frames(&self) -> usize {
        self.recent.len()
    }

    /// Tracks the kept frames that end after a pending acquisition's time
    /// (its own frame ends at it) and before `header`'s frame, in order.
    fn catch_up(&mut self, header: &CloudHeader) {
        let Some(t) = self.pending.and_then(|p| p.t) else {
            return;
        };
        let late: Vec<_> = std::mem::take(&mut self.recent)
            .into_iter()
            .filter(|(h, _)| h.scan_end_s > t + 1e-9 && h.scan_end_s <= header.scan_start_s)
            .collect();
        for (h, points) in &late {
            let mut scratch = FrameResult::new(Default::default());
            self.track_one(h, points, &mut scratch);
        }
    }

    /// [`Self::track`] of one frame, without the catch-up.
    fn track_one(
        &mut self,
        header: &CloudHeader,
        points: &[Point],
        result: &mut FrameResult,
    ) -> Option<TrackOutput> {
        if let Err(e) = self.apply_filter_state(header) {
            result.reason = format!("filter state not applied: {e}");
            result.error = Some(e);
        }
        let refine_from = match self.apply_pending(header) {
            Ok(pose) => pose,
            Err(e) => {
                result.reason = format!("initialisation failed: {e}");
                result.error = Some(e);
                return None;
            }
        };
        if !self.initialized {
            result.reason = "not initialised: awaiting an acquisition".into();
            return None;
        }
        match self
            .tracker
            .process(points, header.scan_start_s, header.scan_end_s)
        {
            Ok(out) => {
                fill_estimate(&mut result.estimate, &out);
                if let Some(given) = refine_from
                    && let Err(e) = self.restart_after(&out, &given)
                {
                    result.error = Some(e);
                }
                result.reason.clone_from(&out.reason);
                Some(out)
            }
            Err(e) => {
                self.fill_prediction(result, header.scan_end_s);
                result.reason = e.to_string();
                result.error = Some(e);
                None
            }
        }
    }

    /// Starts a pending initialisation at `min(t, scan start)` (just before
    /// the scan end), so that this very frame is tracked from it. Returns the
    /// pose when the initialisation time is after the scan start (the
    /// acquisition's own frame, or a reinit command without time): the frame
    /// is then only used to refine the pose, see [`Self::restart_after`].
    fn apply_pending(&mut self, header: &CloudHeader) -> Result<Option<Pose>, TrackError> {
        let Some(p) = self.pending else {
            return Ok(None);
        };
        let (start, end) = (header.scan_start_s, header.scan_end_s);
        if !(start.is_finite() && end.is_finite() && start <= end) {
            return Err(TrackError::InvalidScanTimes {
                start_s: start,
                end_s: end,
                previous_end_s: None,
            });
        }
        let t = p.t.unwrap_or(start).min(start).min(end - 1e-6);
        let (v, w) = zero_rates();
        self.tracker.initialize(t, &p.pose, v, w)?;
        self.pending = None;
        self.initialized = true;
        let within_scan = p.t.is_none_or(|t_init| t_init > start);
        Ok(within_scan.then_some(p.pose))
    }

    /// After the frame an initialisation pose belongs to: the filter must
    /// not learn a rate from "pose of the scan end, placed at the scan
    /// start" (it would learn ω ≈ 0 with confidence, and a tumbling
    /// symmetric target then slides to a symmetric pose). The track restarts
    /// at the scan end from the registered pose (or the given one if the
    /// registration was not good), with zero rates and the initial
    /// uncertainty, as the filter service does with the same estimate.
    fn restart_after(&mut self, out: &TrackOutput, given: &Pose) -> Result<(), TrackError> {
        if out.status == TrackStatus::Tracking {
            return self
                .tracker
                .initialize_from_registration(out.t, &out.t_sensor_target);
        }
        let (v, w) = zero_rates();
        self.tracker.initialize(out.t, given, v, w)
    }

    /// Puts the filter prediction at `t` into the (lost) estimate of
    /// `result`, when there is one.
    pub fn fill_prediction(&self, result: &mut FrameResult, t: f64) {
        if !self.initialized {
            return;
        }
        if let Ok(p) = self.tracker.predict_at(t) {
            result.estimate.set_pose(&p.pose);
        }
    }
}
