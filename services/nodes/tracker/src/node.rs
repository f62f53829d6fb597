//! The tracker node: commands, acquisitions and filter states in, exactly
//! one `PoseEstimate` per cloud out.
//!
//! Before initialisation, for bad input (oversized, all points non-finite)
//! and for frames the tracker refuses, the estimate is `lost`, so
//! downstream services (filter, telemetry, the init service) see every
//! frame. A cloud without the target (empty, or below `loss.min_points`) is
//! answered `lost` at once, with the filter prediction as the pose and no
//! measurement (see [`crate::wire::fill_estimate`]), and fuses nothing: the
//! init service sees the loss on the first such frame and acquires on the
//! first frame with enough points after the gap.
//!
//! A track started by an acquisition that awaits its verification
//! (`Verification::Pending`: init looks again before it confirms it) is published
//! `unconfirmed` instead of `tracking` until the init service's record
//! that confirms that acquisition arrives; everything else is the same
//! (the filter fuses it).

use crate::config::TrackerServiceConfig;
use crate::error::{ControlError, invalid};
use crate::frame::{FrameResult, InputIssue, usable_points};
use crate::track::Track;
use crate::wire::lost_estimate;
use spacepose_geometry::Point;
use spacepose_messages::convert::{acquisition_pose, prediction_from_state};
use spacepose_messages::{
    AcquisitionResult, Cloud, CloudHeader, Command, CommandKind, Counters, FilterState, Message,
    Name, ServiceKind, ServiceState, WireStatus, mode_from_code,
};
use spacepose_runtime::{Ctx, Node, NodeInfo};
use spacepose_tracker::{
    TrackError, TrackOutput, Tracker, TrackerConfig, TrackingMode, TrackingModel,
};
use std::time::Instant;
use tracing::{debug, info, warn};

/// What a command did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommandOutcome {
    /// Addressed to another instance.
    NotForMe,
    /// The tracking mode changed.
    ModeSet(TrackingMode),
    /// The track restarts from the command's pose at the next frame.
    ReinitFromPose,
    /// The track was dropped; the next successful acquisition restarts it.
    ReinitFromAcquisition,
    /// Not a tracker command (swap is for the selector of redundant trackers).
    Ignored(CommandKind),
}

/// The tracker service: a [`Tracker`] fed by the bus.
pub struct TrackerNode {
    track: Track,
    instance: Name,
    max_points: usize,
    /// The tracker's output for the last cloud, when it reached the tracker.
    last_output: Option<TrackOutput>,
    /// The frame of the acquisition whose confirmation the track awaits.
    unconfirmed: Option<u64>,
}

impl Node for TrackerNode {
    const KIND: ServiceKind = ServiceKind::Tracker;
    type Config = TrackerServiceConfig;

    /// Builds the model (logged with the time it took) and the tracker.
    fn new(config: TrackerServiceConfig, info: &NodeInfo) -> anyhow::Result<Self> {
        let started = Instant::now();
        let (model, source) = config.build_model()?;
        info!(
            target = config.target,
            ?source,
            ms = started.elapsed().as_millis() as u64,
            "model ready"
        );
        let node = Self::with_model(config.tracker, model, info.instance, config.max_points)?;
        info!(instance = %info.instance, mode = %node.tracker().mode(), "tracker ready");
        Ok(node)
    }

    fn on_message(&mut self, msg: &Message, ctx: &mut Ctx<'_>) {
        let applied = match msg {
            Message::Command(c) => self.command(c),
            Message::Acquisition(a) => self.acquisition(a),
            Message::FilterState(s) => self.on_filter_state(s),
            _ => Ok(()),
        };
        if let Err(e) = applied {
            ctx.counters.rejected_wire += 1;
            warn!(topic = msg.topic().as_str(), "message refused: {e}");
        }
    }

    fn on_cloud(&mut self, cloud: Cloud<'_>, ctx: &mut Ctx<'_>) {
        ctx.counters.frames_in += 1;
        ctx.counters.last_frame = cloud.header.sequence;
        let result = self.track_frame(cloud.header, cloud.points);
        count(&result, ctx.counters);
        if ctx.send(&Message::Pose(result.estimate)) {
            ctx.counters.frames_out += 1;
        }
    }

    /// Running while tracking, Degraded otherwise (not initialised, lost).
    fn state(&self) -> ServiceState {
        if self.is_tracking() {
            ServiceState::Running
        } else {
            ServiceState::Degraded
        }
    }
}

impl TrackerNode {
    /// A node for `instance` on a built `model`, not initialised
    /// ([`Node::new`] builds the model from the configuration).
    ///
    /// # Errors
    /// An invalid tracker configuration, or an `icp` model that cannot be built.
    pub fn with_model(
        config: TrackerConfig,
        model: TrackingModel,
        instance: Name,
        max_points: usize,
    ) -> Result<Self, TrackError> {
        // The configured lengths are for the reference cell; the target's
        // package scales them (`spacepose_tracker::length_unit`).
        let config = config.scaled_lengths(model.thresholds.length_scale);
        Ok(TrackerNode {
            track: Track::new(config, model)?,
            instance,
            max_points,
            last_output: None,
            unconfirmed: None,
        })
    }

    /// The tracker.
    pub fn tracker(&self) -> &Tracker {
        self.track.tracker()
    }

    /// True when initialised and not lost.
    pub fn is_tracking(&self) -> bool {
        self.track.is_tracking()
    }

    /// The tracker's output for the last cloud, when that cloud reached the
    /// tracker (initialised, usable points, no error); `None` otherwise.
    /// The registration's figures of the frame are in it.
    pub fn last_output(&self) -> Option<&TrackOutput> {
        self.last_output.as_ref()
    }

    /// A successful acquisition restarts the track at the next frame
    /// (rates unknown: zeros, seed 000 §5.2). Returns whether it was accepted.
    /// A pending one leaves the track `unconfirmed` until the record that
    /// confirms it; a confirmation of another acquisition changes nothing.
    ///
    /// # Errors
    /// A message that does not hold a valid pose and time.
    pub fn on_acquisition(&mut self, a: &AcquisitionResult) -> Result<bool, ControlError> {
        if let Some(sequence) = a.confirms() {
            if self.unconfirmed == Some(sequence) {
                self.unconfirmed = None;
                info!(sequence, "the track is confirmed");
            }
            return Ok(false);
        }
        let Some((t, pose)) = acquisition_pose(a).map_err(invalid("AcquisitionResult"))? else {
            return Ok(false);
        };
        self.track.start_at(t, pose);
        self.unconfirmed = a.pending().then_some(a.sequence);
        Ok(true)
    }

    /// True while the track awaits the confirmation of its acquisition.
    pub fn is_unconfirmed(&self) -> bool {
        self.unconfirmed.is_some()
    }

    /// Keeps the filter service's state for the next frame that starts at
    /// or after it (see [`Track::follow`]).
    ///
    /// # Errors
    /// A state with non-finite values or a bad quaternion.
    pub fn on_filter_state(&mut self, s: &FilterState) -> Result<(), ControlError> {
        if let Some(p) = prediction_from_state(s).map_err(invalid("FilterState"))? {
            self.track.follow(p);
        }
        Ok(())
    }

    /// Applies a command addressed to this instance (or to all).
    ///
    /// # Errors
    /// An unknown kind or mode, a bad pose, or a mode the tracker cannot
    /// switch to (its state is then unchanged).
    pub fn on_command(&mut self, c: &Command) -> Result<CommandOutcome, ControlError> {
        if !c.target_instance.is_empty() && c.target_instance != self.instance {
            return Ok(CommandOutcome::NotForMe);
        }
        let kind = CommandKind::from_u8(c.kind).map_err(invalid("Command"))?;
        match kind {
            CommandKind::Mode => {
                let mode = mode_from_code(c.mode).map_err(invalid("Command"))?;
                self.track.set_mode(mode)?;
                Ok(CommandOutcome::ModeSet(mode))
            }
            CommandKind::Reinit if c.has_pose() => {
                let pose = c.pose().map_err(invalid("Command"))?;
                self.track.start_from(pose);
                self.unconfirmed = None;
                Ok(CommandOutcome::ReinitFromPose)
            }
            CommandKind::Reinit => {
                self.track.drop_track()?;
                self.unconfirmed = None;
                Ok(CommandOutcome::ReinitFromAcquisition)
            }
            CommandKind::Swap => Ok(CommandOutcome::Ignored(kind)),
        }
    }

    /// Tracks one frame and returns its estimate (always one).
    pub fn track_frame(&mut self, header: &CloudHeader, points: &[Point]) -> FrameResult {
        self.last_output = None;
        let mode = self.track.tracker().mode();
        let mut result = FrameResult::new(lost_estimate(header, self.instance, mode));
        match usable_points(points, self.max_points, &mut result) {
            Some(points) => self.last_output = self.track.track(header, &points, &mut result),
            None => self.track.fill_prediction(&mut result, header.scan_end_s),
        }
        let tracking = result.estimate.status == WireStatus::Tracking as u8;
        if let (true, Some(acquired)) = (tracking, self.unconfirmed) {
            result.estimate.status = WireStatus::Unconfirmed as u8;
            result.estimate.acquisition_sequence = acquired;
        }
        result
    }

    /// [`Self::on_command`], logged.
    fn command(&mut self, c: &Command) -> Result<(), ControlError> {
        let outcome = self.on_command(c)?;
        info!(issued_by = %c.issued_by, ?outcome, "command");
        Ok(())
    }

    /// [`Self::on_acquisition`], logged when accepted.
    fn acquisition(&mut self, a: &AcquisitionResult) -> Result<(), ControlError> {
        if self.on_acquisition(a)? {
            info!(
                sequence = a.sequence,
                t_s = a.t_s,
                method = a.method,
                "acquisition: (re)initialising at the next frame"
            );
        }
        Ok(())
    }
}

/// A frame's input issue and tracker error in the counters, and the log.
fn count(r: &FrameResult, counters: &mut Counters) {
    let seq = r.estimate.sequence;
    match r.issue {
        Some(InputIssue::Oversized { .. }) => counters.rejected_oversized += 1,
        Some(InputIssue::NonFinite { .. }) => counters.rejected_non_finite += 1,
        None => {}
    }
    if let Some(issue) = r.issue {
        warn!(sequence = seq, ?issue, "bad input frame");
    }
    if let Some(e) = &r.error {
        counters.errors += 1;
        warn!(sequence = seq, "frame not tracked: {e}");
    }
    if !r.reason.is_empty() {
        debug!(
            sequence = seq,
            status = r.estimate.status,
            reason = r.reason,
            "frame"
        );
    }
}

#[cfg(test)]
#[path = "node_tests.rs"]
mod tests;
