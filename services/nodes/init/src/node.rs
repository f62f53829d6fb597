//! The init node: tracker estimates and cropped clouds in, one
//! `AcquisitionResult` per acquisition out.
//!
//! The newest cloud is held (a loss reported later may use it: it is not
//! older than the loss); when the state machine wants a pose and no
//! acquisition runs, the held frame goes to the worker thread. Each
//! wake-up's [`Node::poll`] publishes a finished acquisition and starts
//! the next wanted one; while one runs the node asks to be woken every
//! [`BUSY_POLL_NS`].
//!
//! While the suite tracks an acquired pose not yet confirmed and no
//! acquisition is wanted, the worker verifies the track
//! ([`crate::verify`]): it acquires on a copy of the held frame, and the
//! result is compared with the tracker's pose of that frame instead of
//! being published; a track that a more trusted method contradicts is
//! replaced by publishing the newest contradicting pose as an acquisition.
//! Such an acquisition goes out `Verification::Pending` (the tracker
//! publishes the track `unconfirmed`); once the verifications confirm it,
//! a record `Verification::Confirms` of the same frame follows.

use crate::chain::MethodChain;
use crate::config::InitServiceConfig;
use crate::state::{EstimateInfo, Event, InitConfig, InitStateMachine, InitStats, Phase};
use crate::verify::{TrackedPose, Verdict, Verifier};
use crate::worker::{Done, Frame, Worker};
use spacepose_messages::{
    AcquisitionMethod, AcquisitionResult, Cloud, Message, Name, PoseEstimate, ServiceKind,
    Verification, WireStatus, realtime_ns,
};
use spacepose_runtime::{Ctx, Flow, Node, NodeInfo};
use std::time::Instant;
use tracing::{info, warn};

/// While an acquisition runs, the node is polled this often (ns), so its
/// result goes out promptly.
pub const BUSY_POLL_NS: i64 = 10_000_000;

/// Acquires when the state machine wants a pose.
pub struct InitNode {
    machine: InitStateMachine,
    worker: Worker,
    instance: Name,
    held: Option<Frame>,
    wake_ns: Option<i64>,
    verifier: Option<Verifier>,
    /// The chain's methods, most trusted first.
    methods: Vec<AcquisitionMethod>,
    /// The worker verifies (it does not acquire).
    verifying: bool,
    /// The published acquisition whose track awaits its confirmation.
    pending: Option<AcquisitionResult>,
    /// The frame of the last acquisition confirmed.
    confirmed: Option<u64>,
}

impl Node for InitNode {
    const KIND: ServiceKind = ServiceKind::Init;
    type Config = InitServiceConfig;

    fn new(config: InitServiceConfig, info: &NodeInfo) -> anyhow::Result<Self> {
        let started = Instant::now();
        let (chain, verifier) = config.build()?;
        let methods: Vec<&str> = chain.methods().iter().map(|m| m.as_str()).collect();
        info!(
            target = config.target,
            ?methods,
            ms = started.elapsed().as_millis() as u64,
            "acquisition methods ready"
        );
        Ok(InitNode::with_chain(chain, config.state, info.instance)?.with_verifier(verifier))
    }

    fn on_message(&mut self, msg: &Message, ctx: &mut Ctx<'_>) {
        let Message::Pose(estimate) = msg else {
            return;
        };
        match EstimateInfo::from_wire(estimate) {
            Ok(e) => {
                log_event(self.machine.on_estimate(&e));
                self.note_tracked(&e, estimate);
            }
            Err(err) => {
                ctx.counters.rejected_wire += 1;
                warn!("estimate refused: {err}");
            }
        }
    }

    fn on_cloud(&mut self, cloud: Cloud<'_>, ctx: &mut Ctx<'_>) {
        let header = *cloud.header;
        ctx.counters.frames_in += 1;
        ctx.counters.last_frame = header.sequence;
        log_event(self.machine.on_frame(header.sequence));
        // The held frame's buffer is reused when it was not used.
        let mut points = self.held.take().map(|f| f.points).unwrap_or_default();
        points.clear();
        points.extend_from_slice(cloud.points);
        self.held = Some(Frame {
            sequence: header.sequence,
            scan_end_s: header.scan_end_s,
            points,
        });
    }

    fn poll(&mut self, ctx: &mut Ctx<'_>) -> Flow {
        if let Some(done) = self.worker.finished() {
            if std::mem::take(&mut self.verifying) {
                self.verified(done, ctx);
            } else {
                self.publish(done, ctx);
            }
        }
        self.start_if_wanted();
        self.wake_ns = self.worker.busy().then(|| ctx.now_ns + BUSY_POLL_NS);
        Flow::Continue
    }

    fn next_wake_ns(&self) -> Option<i64> {
        self.wake_ns
    }

    fn stop(&mut self, _: &mut Ctx<'_>) {
        info!(stats = ?self.machine.stats(), "init service stopping");
    }
}

impl InitNode {
    /// A node over a built `chain`, with the state machine's timing
    /// `state`, publishing as `instance`; starts the worker thread.
    ///
    /// # Errors
    /// An invalid `state`, or the thread cannot be started.
    pub fn with_chain(
        chain: MethodChain,
        state: InitConfig,
        instance: Name,
    ) -> anyhow::Result<Self> {
        Ok(InitNode {
            machine: InitStateMachine::new(state)?,
            methods: chain.methods(),
            worker: Worker::spawn(chain)?,
            instance,
            held: None,
            wake_ns: None,
            verifier: None,
            verifying: false,
            pending: None,
            confirmed: None,
        })
    }

    /// This node verifying its hand-overs with `verifier` (when enabled).
    pub fn with_verifier(mut self, verifier: Verifier) -> Self {
        self.verifier = verifier.enabled().then_some(verifier);
        self
    }

    /// Where the service stands.
    pub fn phase(&self) -> Phase {
        self.machine.phase()
    }

    /// Acquisitions, acceptances, rejections and losses so far.
    pub fn stats(&self) -> &InitStats {
        self.machine.stats()
    }

    /// True while an acquisition runs.
    pub fn busy(&self) -> bool {
        self.worker.busy()
    }

    /// Hands the held frame to the worker when the state machine wants it
    /// and no acquisition is running; else, while the suite tracks, a copy
    /// of it when a verification is due.
    fn start_if_wanted(&mut self) {
        if self.worker.busy() {
            return;
        }
        let wanted = self
            .held
            .as_ref()
            .is_some_and(|h| self.machine.wants(h.sequence));
        if let Some(frame) = self.held.take_if(|_| wanted) {
            self.worker.start(frame);
            return;
        }
        let tracking = self.machine.phase() == Phase::Tracking;
        let due = |h: &Frame| self.verifier.as_ref().is_some_and(|v| v.due(h.sequence));
        if let Some(frame) = self.held.as_ref().filter(|h| tracking && due(h)) {
            self.verifying = true;
            self.worker.start(frame.clone());
        }
    }

    /// Gives the verifier the tracker's `tracking` pose of a frame of the
    /// current track (not one started before the last hand-over).
    fn note_tracked(&mut self, e: &EstimateInfo, estimate: &PoseEstimate) {
        let current = self.machine.of_current_track(e);
        if current && e.status == WireStatus::Unconfirmed {
            self.adopt(estimate);
        }
        let Some(verifier) = &mut self.verifier else {
            return;
        };
        let tracking = e.status.is_tracked() && self.machine.phase() == Phase::Tracking;
        if let (true, true, Ok(pose)) = (current, tracking, estimate.pose()) {
            verifier.on_tracked(TrackedPose {
                sequence: e.sequence,
                t_sensor_target: pose,
            });
        }
    }

    /// An `unconfirmed` track this node does not know of (it was restarted
    /// after the acquisition went out): its verification is taken over and
    /// confirmed with the acquisition's frame the tracker names. The method
    /// that acquired it is unknown: it counts as the most trusted one whose
    /// tracks are verified (with `confirm_first_method`, the first: by
    /// agreements only).
    fn adopt(&mut self, estimate: &PoseEstimate) {
        let acquired = estimate.acquisition_sequence;
        let known = self.pending.is_some_and(|p| p.sequence == acquired);
        let (Some(verifier), false) = (
            &mut self.verifier,
            known || self.confirmed == Some(acquired),
        ) else {
            return;
        };
        let origin = (0..self.methods.len()).find(|&rank| verifier.verifies(rank));
        let (Some(origin), Ok(pose)) = (origin, estimate.pose()) else {
            return;
        };
        verifier.reset(Some(origin), Some(acquired));
        let mut msg = AcquisitionResult::new();
        (msg.sequence, msg.t_s, msg.instance) = (acquired, estimate.t_s, self.instance);
        (msg.method, msg.success) = (self.methods[origin] as u8, 1);
        msg.verification = Verification::Pending as u8;
        msg.set_pose(&pose);
        self.pending = Some(msg);
        info!(
            acquired,
            "an unconfirmed track of an earlier acquisition: verifying it"
        );
    }

    /// A verification finished: compared with the track; a track the
    /// verifications contradict is replaced by the newest pose found.
    fn verified(&mut self, done: Done, ctx: &mut Ctx<'_>) {
        let Some(verifier) = &mut self.verifier else {
            return;
        };
        if self.machine.phase() != Phase::Tracking {
            return;
        }
        let methods = &self.methods;
        let accepted = done.acquisition.accepted().and_then(|a| {
            Some((
                a.outcome.as_ref().ok()?.t_sensor_target,
                rank(methods, a.method)?,
            ))
        });
        let verdict = verifier.on_result(done.sequence, accepted);
        info!(
            sequence = done.sequence,
            ?verdict,
            "verification: {}",
            done.acquisition.summary()
        );
        if let Verdict::Agrees { confirmed: true } = verdict {
            self.confirm(ctx);
        }
        if let Verdict::Replace { off_deg, .. } = verdict {
            warn!(
                sequence = done.sequence,
                off_deg, "the verifications contradict the track: the newest pose replaces it"
            );
            self.publish(done, ctx);
        }
    }

    /// Publishes a finished acquisition and tells the state machine.
    fn publish(&mut self, done: Done, ctx: &mut Ctx<'_>) {
        let acquisition = &done.acquisition;
        // An empty frame is an observation (the target is not in view:
        // ingest forwards it on purpose), not bad input: not counted.
        if done.points_in > 0 && acquisition.points < done.points_in {
            ctx.counters.rejected_non_finite += 1;
        }
        let mut msg = acquisition.to_wire(done.sequence, done.scan_end_s, self.instance);
        let origin = AcquisitionMethod::from_u8(msg.method)
            .ok()
            .and_then(|m| rank(&self.methods, m))
            .filter(|_| msg.success == 1);
        let verified =
            origin.is_some_and(|r| self.verifier.as_ref().is_some_and(|v| v.verifies(r)));
        if verified {
            msg.verification = Verification::Pending as u8;
        }
        // Stamped after the send: a tracker frame started before the result
        // went out must not count as started after it (hand-over check).
        // The wake-up time `now_ns` is earlier; a LocalBus clock ahead of
        // the wall clock is never passed.
        let published_ns = ctx
            .send(&Message::Acquisition(msg))
            .then(|| realtime_ns().max(ctx.now_ns));
        if published_ns.is_some() {
            ctx.counters.frames_out += 1;
        }
        let accepted = msg.success == 1 && published_ns.is_some();
        info!(
            sequence = done.sequence,
            success = msg.success,
            method = msg.method,
            pending = verified,
            f_conv_m2 = msg.f_conv_m2,
            time_ms = acquisition.time_ms,
            "acquisition: {}",
            acquisition.summary()
        );
        if accepted {
            if let Some(v) = &mut self.verifier {
                v.reset(origin, Some(done.sequence));
            }
            self.pending = verified.then_some(msg);
        }
        log_event(
            self.machine
                .on_acquisition(done.sequence, accepted, published_ns),
        );
    }

    /// The verifications confirmed the track: the record that says so.
    fn confirm(&mut self, ctx: &mut Ctx<'_>) {
        let Some(mut msg) = self.pending.take() else {
            return;
        };
        msg.verification = Verification::Confirms as u8;
        self.confirmed = Some(msg.sequence);
        if ctx.send(&Message::Acquisition(msg)) {
            ctx.counters.frames_out += 1;
        }
        info!(
            sequence = msg.sequence,
            "the verifications confirm the track"
        );
    }
}

/// The rank of `method` in the chain (0: the most trusted).
fn rank(methods: &[AcquisitionMethod], method: AcquisitionMethod) -> Option<usize> {
    methods.iter().position(|m| *m == method)
}

fn log_event(event: Event) {
    match event {
        Event::None => {}
        Event::NoTrack { frame } => info!(frame, "no tracker tracks: acquiring"),
        Event::LossDetected { frame } => info!(frame, "track lost: acquiring"),
        Event::HandoverFailed { frame } => {
            warn!(
                frame,
                "the tracker lost the handed-over pose: acquiring again"
            )
        }
        Event::TrackerTracking { frame } => info!(frame, "the tracker tracks"),
        Event::Accepted {
            frame,
            delay_frames,
        } => info!(frame, ?delay_frames, "pose acquired and handed over"),
        Event::Rejected { frame, retry_from } => {
            info!(
                frame,
                retry_from, "acquisition rejected: retrying on a later frame"
            )
        }
    }
}

#[cfg(test)]
#[path = "node_tests.rs"]
mod tests;
