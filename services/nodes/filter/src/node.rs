//! The filter node: commands, acquisitions and tracker estimates in, the
//! `FilterState` out after every change and every `state_period_ms`.
//!
//! A single tracker's estimate (no primary configured, or the primary's
//! own) is decided and fused as it arrives, and the state published at the
//! poll that follows; only a frame waiting for its primary waits for its
//! deadline ([`Node::next_wake_ns`]). The runtime's clock (`ctx.now_ns`)
//! drives the deadlines and the period, so the node runs the same on the
//! bus and on a [`spacepose_runtime::LocalBus`].

use crate::choice::{Offer, Reason};
use crate::config::FilterServiceConfig;
use crate::error::FilterNodeError;
use crate::failover::RoleChange;
use crate::fusion::{EstimateOutcome, Fuser, Fusion};
use crate::publication::Publication;
use crate::snapshot::load_snapshot;
use spacepose_filter::RelativeMotionFilter;
use spacepose_messages::{
    AcquisitionResult, Command, CommandKind, FilterState, Message, PoseEstimate, ServiceKind,
    ServiceState,
};
use spacepose_runtime::{Counters, Ctx, Flow, Node, NodeInfo};
use std::time::Duration;
use tracing::{debug, info, warn};

/// The filter service: the authoritative relative-motion state, published.
#[derive(Debug, Clone)]
pub struct FilterNode {
    fuser: Fuser,
    publication: Publication,
    /// Errors met before the first poll (a bad snapshot), for the counters.
    startup_errors: u64,
}

impl Node for FilterNode {
    const KIND: ServiceKind = ServiceKind::Filter;
    type Config = FilterServiceConfig;

    /// An uninitialised node, resumed from a fresh snapshot when there is one.
    fn new(config: FilterServiceConfig, info: &NodeInfo) -> anyhow::Result<Self> {
        let mut node = Self::from_config(&config)?;
        node.resume(&config);
        info!(instance = %info.instance, primary = ?node.primary(), "filter ready");
        Ok(node)
    }

    fn on_message(&mut self, msg: &Message, ctx: &mut Ctx<'_>) {
        match msg {
            Message::Command(c) => self.command(c, ctx.counters),
            Message::Acquisition(a) => self.acquisition(a, ctx.counters),
            Message::Pose(e) => self.estimate(e, ctx),
            _ => {}
        }
    }

    /// Frames past their deadline, role changes, then the state when it
    /// changed or is due.
    fn poll(&mut self, ctx: &mut Ctx<'_>) -> Flow {
        ctx.counters.errors += std::mem::take(&mut self.startup_errors);
        let fusions = self.poll_deadlines(ctx.now_ns);
        report(&fusions, ctx.counters);
        for c in self.take_role_changes() {
            warn!(from = c.from, to = c.to, cause = ?c.cause, from_frame = c.from_frame, "acting primary changed");
        }
        let state = self.filter_state();
        self.publication.flush(&state, ctx);
        Flow::Continue
    }

    /// The next frame deadline or periodic state, whichever comes first.
    fn next_wake_ns(&self) -> Option<i64> {
        [self.next_deadline_ns(), self.publication.next_ns()]
            .into_iter()
            .flatten()
            .min()
    }

    /// Running once initialised, Degraded before.
    fn state(&self) -> ServiceState {
        if self.filter().is_initialized() {
            ServiceState::Running
        } else {
            ServiceState::Degraded
        }
    }
}

impl FilterNode {
    /// An uninitialised node, without looking for a snapshot ([`Node::new`]
    /// resumes from it).
    ///
    /// # Errors
    /// An invalid configuration.
    pub fn from_config(config: &FilterServiceConfig) -> Result<Self, FilterNodeError> {
        Ok(FilterNode {
            fuser: Fuser::new(config)?,
            publication: Publication::new(config.state_period_ms, config.snapshot_file.clone()),
            startup_errors: 0,
        })
    }

    /// The filter.
    pub fn filter(&self) -> &RelativeMotionFilter {
        self.fuser.filter()
    }

    /// The filter and its selector.
    pub fn fuser(&self) -> &Fuser {
        &self.fuser
    }

    /// State changes (initialisations and fused estimates) so far.
    pub fn updates(&self) -> u64 {
        self.fuser.updates()
    }

    /// The state to publish (uninitialised until an acquisition arrives).
    pub fn filter_state(&self) -> FilterState {
        self.fuser.state()
    }

    /// The acting primary instance of the selector (None: first arrival
    /// wins): the preferred one, unless a standby was promoted.
    pub fn primary(&self) -> Option<&str> {
        self.fuser.selector().primary()
    }

    /// The preferred primary (configured, or named by the last swap).
    pub fn preferred_primary(&self) -> Option<&str> {
        self.fuser.selector().preferred()
    }

    /// The earliest frame deadline the node waits for (ns, the node's clock).
    pub fn next_deadline_ns(&self) -> Option<i64> {
        self.fuser.selector().next_deadline_ns()
    }

    /// Promotions and reverts of the acting primary since the last call
    /// (a poll logs and clears them).
    pub fn take_role_changes(&mut self) -> Vec<RoleChange> {
        self.fuser.take_role_changes()
    }

    /// (Re)initialises on a successful acquisition (see [`Fuser::on_acquisition`]).
    pub fn on_acquisition(&mut self, a: &AcquisitionResult) -> Result<bool, FilterNodeError> {
        let changed = self.fuser.on_acquisition(a)?;
        if changed {
            self.publication.changed();
        }
        Ok(changed)
    }

    /// Resumes from a persisted state (see [`Fuser::restore`]).
    pub fn restore(&mut self, s: &FilterState) -> Result<bool, FilterNodeError> {
        let restored = self.fuser.restore(s)?;
        if restored {
            self.publication.resumed();
        }
        Ok(restored)
    }

    /// Makes `instance` the primary from the next undecided frame on (swap
    /// command); returns the fusions this decides at once.
    pub fn set_primary(&mut self, instance: &str) -> Vec<Fusion> {
        let fusions = self.fuser.set_primary(instance);
        self.note(&fusions);
        fusions
    }

    /// Offers a tracker estimate received at `now_ns` (see
    /// [`Fuser::on_estimate`]). Errors on a bad message.
    pub fn on_estimate(
        &mut self,
        e: &PoseEstimate,
        now_ns: i64,
    ) -> Result<(Offer, Vec<Fusion>), FilterNodeError> {
        let (offer, fusions) = self.fuser.on_estimate(e, now_ns)?;
        self.note(&fusions);
        Ok((offer, fusions))
    }

    /// Decides and fuses the frames whose deadline has passed at `now_ns`.
    pub fn poll_deadlines(&mut self, now_ns: i64) -> Vec<Fusion> {
        let fusions = self.fuser.poll_deadlines(now_ns);
        self.note(&fusions);
        fusions
    }

    /// A fusion that changed the state is published (and persisted).
    fn note(&mut self, fusions: &[Fusion]) {
        if fusions.iter().any(Fusion::changed_state) {
            self.publication.changed();
        }
    }

    /// Restores the state of a previous filter process from a fresh
    /// snapshot (`snapshot_file`). A bad snapshot is logged, counted at the
    /// first poll and ignored.
    fn resume(&mut self, config: &FilterServiceConfig) {
        let Some(path) = &config.snapshot_file else {
            return;
        };
        let max_age = Duration::from_secs_f64(config.snapshot_max_age_s);
        let restored = load_snapshot(path, max_age).and_then(|s| match s {
            Some(s) => self.restore(&s).map(|ok| ok.then_some(s.t_s)),
            None => Ok(None),
        });
        match restored {
            Ok(Some(t_s)) => {
                info!(path = %path.display(), t_s, "resumed from the previous filter's snapshot");
            }
            Ok(None) => {}
            Err(e) => {
                self.startup_errors += 1;
                warn!("snapshot ignored: {e}");
            }
        }
    }

    /// Applies swap commands (the target instance becomes the primary);
    /// other commands are for the trackers.
    fn command(&mut self, c: &Command, counters: &mut Counters) {
        match CommandKind::from_u8(c.kind) {
            Ok(CommandKind::Swap) if !c.target_instance.is_empty() => {
                let new = c.target_instance.as_str().to_string();
                info!(
                    issued_by = %c.issued_by,
                    old = ?self.primary(),
                    new,
                    "swap: new primary from the next frame"
                );
                let fusions = self.set_primary(&new);
                report(&fusions, counters);
            }
            Ok(CommandKind::Swap) => {
                counters.rejected_wire += 1;
                warn!(issued_by = %c.issued_by, "swap command without a target instance refused");
            }
            Ok(_) => {}
            Err(e) => {
                counters.rejected_wire += 1;
                warn!("command refused: {e}");
            }
        }
    }

    fn acquisition(&mut self, a: &AcquisitionResult, counters: &mut Counters) {
        match self.on_acquisition(a) {
            Ok(true) => info!(
                sequence = a.sequence,
                t_s = a.t_s,
                "initialised by an acquisition"
            ),
            Ok(false) => info!(sequence = a.sequence, "failed acquisition ignored"),
            Err(e) => {
                counters.rejected_wire += 1;
                warn!("acquisition refused: {e}");
            }
        }
    }

    fn estimate(&mut self, e: &PoseEstimate, ctx: &mut Ctx<'_>) {
        ctx.counters.frames_in += 1;
        ctx.counters.last_frame = e.sequence;
        match self.on_estimate(e, ctx.now_ns) {
            Ok((_, fusions)) => report(&fusions, ctx.counters),
            Err(err) => {
                ctx.counters.rejected_non_finite += 1;
                warn!(sequence = e.sequence, "estimate refused: {err}");
            }
        }
    }
}

/// Logs the selector's decisions; a failed fusion is counted in `errors`.
fn report(fusions: &[Fusion], counters: &mut Counters) {
    for f in fusions {
        if !matches!(f.reason, Reason::Primary | Reason::FirstArrival) {
            info!(sequence = f.sequence, instance = f.instance, reason = ?f.reason, "standby estimate taken");
        }
        match &f.outcome {
            Ok(EstimateOutcome::InitializedFromEstimate) => info!(
                sequence = f.sequence,
                instance = f.instance,
                "initialised from a tracking estimate"
            ),
            Ok(o) if !o.changed_state() => {
                debug!(sequence = f.sequence, outcome = ?o, "estimate not fused");
            }
            Ok(_) => {}
            Err(err) => {
                counters.errors += 1;
                warn!(sequence = f.sequence, "filter update failed: {err}");
            }
        }
    }
}

#[cfg(test)]
#[path = "node_tests.rs"]
mod tests;
