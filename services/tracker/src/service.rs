//! The tracker service's logic without any bus: what to do with each
//! acquisition, filter state, command and cloud, and the estimate to
//! publish for every frame. `src/main.rs` only moves messages.
//!
//! Exactly one `PoseEstimate` is produced per cloud: before initialisation,
//! for bad input (oversized, all points non-finite) and for frames the
//! tracker refuses, it is a `lost` estimate, so downstream services
//! (filter, telemetry, the init service) see every frame.
//!
//! An empty cloud (or one below `loss.min_points`) is not bad input: ingest
//! forwards a well-formed frame without the target as the observation
//! "target not seen" (e.g. the sensor looked away). The tracker answers it
//! `lost` at once, with the filter prediction as the pose and no
//! measurement (zero iterations, inliers and covariance; see
//! [`crate::wire::fill_estimate`]), and fuses nothing: the init service
//! sees the loss on the first such frame and acquires on the first frame
//! with enough points after the gap.

use crate::config::TrackerConfig;
use crate::error::TrackError;
use crate::model::TrackingModel;
use crate::output::TrackOutput;
use crate::status::TrackStatus;
use crate::tracker::Tracker;
use crate::wire::{fill_estimate, lost_estimate, mode_from_wire};
use spacepose_filter::Prediction;
use spacepose_filter::wire::{acquisition_pose, prediction_from_state};
use spacepose_geometry::{Point, Pose};
use spacepose_messages::{
    AcquisitionResult, CloudHeader, Command, CommandKind, FilterState, Name, PoseEstimate, WireMode,
};
use std::borrow::Cow;

/// Why a frame was not handed to the tracker (or only partly).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputIssue {
    /// More points than `max_points`.
    Oversized {
        /// Points in the frame.
        points: usize,
        /// The limit.
        max_points: usize,
    },
    /// Some points had NaN/infinite values; they were dropped. With
    /// `kept == 0` the frame was not tracked.
    NonFinite {
        /// Points dropped.
        dropped: usize,
        /// Finite points kept.
        kept: usize,
    },
}

/// The answer for one cloud.
#[derive(Debug)]
pub struct FrameResult {
    /// The estimate to publish (always one per frame).
    pub estimate: PoseEstimate,
    /// A problem with the input, to log and count.
    pub issue: Option<InputIssue>,
    /// A tracker error (misuse, bad scan times), to log and count.
    pub error: Option<TrackError>,
    /// Why the estimate is degraded or lost (empty when tracking).
    pub reason: String,
}

/// What a command did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommandOutcome {
    /// Addressed to another instance.
    NotForMe,
    /// The tracking mode changed.
    ModeSet(WireMode),
    /// The track restarts from the command's pose at the next frame.
    ReinitFromPose,
    /// The track was dropped; the next successful acquisition restarts it.
    ReinitFromAcquisition,
    /// Not a tracker command (swap is for the selector of redundant trackers).
    Ignored(CommandKind),
}

/// An initialisation applied at the next usable frame.
#[derive(Debug, Clone, Copy)]
struct PendingInit {
    /// Time of validity of the pose; `None` = the next frame's scan start.
    t: Option<f64>,
    pose: Pose,
}

/// The tracker service: a [`Tracker`] fed by the bus.
pub struct TrackerNode {
    tracker: Tracker,
    model: TrackingModel,
    instance: Name,
    max_points: usize,
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
}

impl TrackerNode {
    /// A node for `instance`, not initialised.
    pub fn new(
        config: TrackerConfig,
        model: TrackingModel,
        instance: Name,
        max_points: usize,
    ) -> Result<Self, TrackError> {
        Ok(Self {
            tracker: Tracker::new(config, model.clone())?,
            model,
            instance,
            max_points,
            pending: None,
            initialized: false,
            warm_start: true,
            pending_state: None,
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

    /// A successful acquisition restarts the track at the next frame
    /// (rates unknown: zeros, seed 000 §5.2). Returns whether it was accepted.
    pub fn on_acquisition(&mut self, a: &AcquisitionResult) -> Result<bool, TrackError> {
        let accepted = acquisition_pose(a).map_err(|e| invalid("AcquisitionResult", e))?;
        let Some((t, pose)) = accepted else {
            return Ok(false);
        };
        self.pending = Some(PendingInit { t: Some(t), pose });
        Ok(true)
    }

    /// Keeps the filter service's state to replace the local filter with
    /// before the next frame that starts at or after it (ignored while an
    /// initialisation is pending; states older than the local one are
    /// ignored when applied). A fresh instance that was never initialised
    /// starts from it (warm start of a restarted or swapped-in tracker,
    /// issue 7).
    pub fn on_filter_state(&mut self, s: &FilterState) -> Result<(), TrackError> {
        let prediction = prediction_from_state(s).map_err(|e| invalid("FilterState", e))?;
        if let Some(p) = prediction
            && self.pending.is_none()
            && (self.initialized || self.warm_start)
            && self.pending_state.is_none_or(|old| old.t <= p.t)
        {
            self.pending_state = Some(p);
        }
        Ok(())
    }

    /// Applies the kept filter state when it is not after the scan start.
    fn apply_filter_state(&mut self, header: &CloudHeader) -> Result<(), TrackError> {
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

    /// Applies a command addressed to this instance (or to all).
    pub fn on_command(&mut self, c: &Command) -> Result<CommandOutcome, TrackError> {
        if !c.target_instance.is_empty() && c.target_instance != self.instance {
            return Ok(CommandOutcome::NotForMe);
        }
        let kind = CommandKind::from_u8(c.kind).map_err(|e| invalid("Command", e))?;
        match kind {
            CommandKind::Mode => {
                let mode = WireMode::from_u8(c.mode).map_err(|e| invalid("Command", e))?;
                self.tracker.set_mode(mode_from_wire(mode))?;
                Ok(CommandOutcome::ModeSet(mode))
            }
            CommandKind::Reinit if c.has_pose() => {
                let pose = c.pose().map_err(|e| invalid("Command", e))?;
                self.pending = Some(PendingInit { t: None, pose });
                Ok(CommandOutcome::ReinitFromPose)
            }
            CommandKind::Reinit => {
                let config = self.tracker.config().clone();
                self.tracker = Tracker::new(config, self.model.clone())?;
                self.initialized = false;
                self.warm_start = false;
                self.pending = None;
                self.pending_state = None;
                Ok(CommandOutcome::ReinitFromAcquisition)
            }
            CommandKind::Swap => Ok(CommandOutcome::Ignored(kind)),
        }
    }

    /// Tracks one frame and returns its estimate.
    pub fn on_cloud(&mut self, header: &CloudHeader, points: &[Point]) -> FrameResult {
        let mut result = FrameResult {
            estimate: lost_estimate(header, self.instance, self.tracker.mode()),
            issue: None,
            error: None,
            reason: String::new(),
        };
        let points = match self.check_input(points, &mut result) {
            Some(p) => p,
            None => {
                self.fill_prediction(&mut result.estimate, header.scan_end_s);
                return result;
            }
        };
        if let Err(e) = self.apply_filter_state(header) {
            result.reason = format!("filter state not applied: {e}");
            result.error = Some(e);
        }
        let refine_from = match self.apply_pending(header) {
            Ok(pose) => pose,
            Err(e) => {
                result.reason = format!("initialisation failed: {e}");
                result.error = Some(e);
                return result;
            }
        };
        if !self.initialized {
            result.reason = "not initialised: awaiting an acquisition".into();
            return result;
        }
        match self
            .tracker
            .process(&points, header.scan_start_s, header.scan_end_s)
        {
            Ok(out) => {
                fill_estimate(&mut result.estimate, &out);
                if let Some(given) = refine_from
                    && let Err(e) = self.restart_after(&out, &given)
                {
                    result.error = Some(e);
                }
                result.reason = out.reason;
            }
            Err(e) => {
                self.fill_prediction(&mut result.estimate, header.scan_end_s);
                result.reason = e.to_string();
                result.error = Some(e);
            }
        }
        result
    }

    /// The finite points of an acceptable frame; `None` (and the issue
    /// recorded) when the frame cannot be tracked at all.
    fn check_input<'a>(
        &self,
        points: &'a [Point],
        result: &mut FrameResult,
    ) -> Option<Cow<'a, [Point]>> {
        // An empty cloud is no issue: it goes to the tracker (no measurement).
        let issue = if points.len() > self.max_points {
            InputIssue::Oversized {
                points: points.len(),
                max_points: self.max_points,
            }
        } else {
            let kept = points.iter().filter(|p| p.is_finite()).count();
            if kept == points.len() {
                return Some(Cow::Borrowed(points));
            }
            result.issue = Some(InputIssue::NonFinite {
                dropped: points.len() - kept,
                kept,
            });
            if kept > 0 {
                let finite = points.iter().copied().filter(Point::is_finite).collect();
                return Some(Cow::Owned(finite));
            }
            result.reason = "every point is non-finite".into();
            return None;
        };
        result.reason = format!("input rejected: {issue:?}");
        result.issue = Some(issue);
        None
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
        let zero = nalgebra::Vector3::zeros();
        self.tracker.initialize(t, &p.pose, zero, zero)?;
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
        let pose = if out.status == TrackStatus::Tracking {
            &out.t_sensor_target
        } else {
            given
        };
        let zero = nalgebra::Vector3::zeros();
        self.tracker.initialize(out.t, pose, zero, zero)
    }

    /// Puts the filter prediction at `t` into a lost estimate, when there is one.
    fn fill_prediction(&self, e: &mut PoseEstimate, t: f64) {
        if !self.initialized {
            return;
        }
        if let Ok(p) = self.tracker.predict_at(t) {
            e.set_pose(&p.pose);
        }
    }
}

fn invalid(what: &'static str, e: impl ToString) -> TrackError {
    TrackError::InvalidMessage {
        what,
        reason: e.to_string(),
    }
}

#[cfg(test)]
#[path = "service_tests.rs"]
mod tests;
