//! When the filter node publishes its state and writes its snapshot: after
//! every change (published and persisted), after a resume from a snapshot
//! (published), and every `state_period_ms` (published: the heartbeat for
//! late joiners such as a restarted tracker or telemetry).

use crate::snapshot::save_snapshot;
use spacepose_messages::{FilterState, Message};
use spacepose_runtime::{Counters, Ctx};
use std::path::PathBuf;
use tracing::warn;

/// The publication and persistence of the state, on the node's clock.
#[derive(Debug, Clone)]
pub struct Publication {
    period_ns: Option<i64>,
    /// When the state last went out (or the first poll, before any).
    last_ns: Option<i64>,
    publish: bool,
    persist: bool,
    snapshot: Option<PathBuf>,
}

impl Publication {
    /// Every `state_period_ms` (0: only on changes), persisting to
    /// `snapshot` when set.
    pub fn new(state_period_ms: u64, snapshot: Option<PathBuf>) -> Self {
        let period_ns =
            i64::try_from(state_period_ms.saturating_mul(1_000_000)).unwrap_or(i64::MAX);
        Publication {
            period_ns: (state_period_ms > 0).then_some(period_ns),
            last_ns: None,
            publish: false,
            persist: false,
            snapshot,
        }
    }

    /// The state changed: publish and persist it at the next flush.
    pub fn changed(&mut self) {
        self.publish = true;
        self.persist = true;
    }

    /// The state was resumed from the snapshot: publish it at the next
    /// flush (the file already holds it).
    pub fn resumed(&mut self) {
        self.publish = true;
    }

    /// When the periodic state is next due (ns); `None` before the first
    /// flush or without a period.
    pub fn next_ns(&self) -> Option<i64> {
        Some(self.last_ns?.saturating_add(self.period_ns?))
    }

    /// Publishes `state` when it changed or the period has passed at
    /// `ctx.now_ns` (counted in `frames_out`), and persists it when it
    /// changed and is initialised.
    pub fn flush(&mut self, state: &FilterState, ctx: &mut Ctx<'_>) {
        let last = *self.last_ns.get_or_insert(ctx.now_ns);
        let periodic = self
            .period_ns
            .is_some_and(|p| ctx.now_ns.saturating_sub(last) >= p);
        if self.publish || periodic {
            if ctx.send(&Message::FilterState(*state)) {
                ctx.counters.frames_out += 1;
            }
            self.last_ns = Some(ctx.now_ns);
        }
        if self.persist {
            self.write(state, ctx.counters);
        }
        self.publish = false;
        self.persist = false;
    }

    /// Writes the state to the snapshot file (if configured).
    fn write(&self, state: &FilterState, counters: &mut Counters) {
        if let Some(path) = &self.snapshot
            && state.initialized != 0
            && let Err(e) = save_snapshot(path, state)
        {
            counters.errors += 1;
            warn!("{e}");
        }
    }
}
