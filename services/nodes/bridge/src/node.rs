//! The bridge node: the runtime's link forwards the routes; the node turns
//! their figures into health counters and state, and writes `stats_file`.

use crate::config::BridgeNodeConfig;
use crate::link::link_spec;
use crate::stats::{Schedule, write_stats};
use spacepose_bus::BridgeStats;
use spacepose_messages::{Counters, Names, ServiceKind, ServiceState};
use spacepose_runtime::{Ctx, Flow, LinkSpec, LinkStatus, Node, NodeInfo};
use std::path::PathBuf;

/// Reports the routes of a host of a partitioned suite.
pub struct BridgeNode {
    stats_file: Option<PathBuf>,
    schedule: Schedule,
    /// The routes' figures already in the counters.
    seen: BridgeStats,
    /// False once the routes stopped.
    running: bool,
}

impl Node for BridgeNode {
    const KIND: ServiceKind = ServiceKind::Bridge;
    type Config = BridgeNodeConfig;

    fn link(config: &BridgeNodeConfig, _: &Names) -> anyhow::Result<Option<LinkSpec>> {
        Ok(Some(link_spec(&config.0)?))
    }

    fn new(config: BridgeNodeConfig, _: &NodeInfo) -> anyhow::Result<Self> {
        let config = config.0;
        let suite = config.suite()?;
        tracing::info!(
            suite = suite.prefix(),
            routes = config.routes.len(),
            stats_file = ?config.stats_file,
            "bridge of a partitioned suite"
        );
        Ok(BridgeNode {
            stats_file: config.stats_file,
            schedule: Schedule::every(config.stats_period_s),
            seen: BridgeStats::default(),
            running: true,
        })
    }

    fn poll(&mut self, ctx: &mut Ctx<'_>) -> Flow {
        let Some(link) = ctx.link else {
            return Flow::Continue;
        };
        self.report(link, ctx.counters);
        if self.schedule.due(ctx.now_ns)
            && let Some(path) = &self.stats_file
        {
            write_stats(path, link);
        }
        Flow::Continue
    }

    fn next_wake_ns(&self) -> Option<i64> {
        self.stats_file.as_ref().and(self.schedule.next_ns())
    }

    fn state(&self) -> ServiceState {
        if self.running {
            ServiceState::Running
        } else {
            ServiceState::Degraded
        }
    }

    fn stop(&mut self, ctx: &mut Ctx<'_>) {
        let Some(link) = ctx.link else {
            return;
        };
        self.report(link, ctx.counters);
        if let Some(path) = &self.stats_file {
            write_stats(path, link);
        }
    }
}

impl BridgeNode {
    /// Adds what the routes did since the last report to the counters
    /// (frames_in: forwarded from zenoh; frames_out: forwarded to zenoh;
    /// rejected_wire; errors) and notes whether they still run.
    fn report(&mut self, link: &LinkStatus, counters: &mut Counters) {
        let (now, seen) = (&link.stats, &self.seen);
        counters.frames_in += now
            .forwarded_from_zenoh
            .saturating_sub(seen.forwarded_from_zenoh);
        counters.frames_out += now
            .forwarded_to_zenoh
            .saturating_sub(seen.forwarded_to_zenoh);
        counters.rejected_wire += now.rejected_wire.saturating_sub(seen.rejected_wire);
        counters.errors += now.errors.saturating_sub(seen.errors);
        self.seen = *now;
        // Without routes the runtime starts no forwarding: nothing stopped.
        let running = link.running || link.routes.is_empty();
        if self.running && !running {
            tracing::error!("the routes stopped: nothing crosses this host's link any more");
        }
        self.running = running;
    }
}

#[cfg(test)]
#[path = "node_tests.rs"]
mod tests;
