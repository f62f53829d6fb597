//! What a service is to the runtime: a bus-free [`Node`] that takes
//! messages and clouds and sends its outputs through a [`Ctx`].
//!
//! The runtime owns the loop (arguments, logging, configuration, bus,
//! health, waiting, draining, deadlines, shutdown: [`crate::run`]); the
//! node owns the decisions. The same node runs in its process on the bus
//! and, with [`crate::LocalBus`], in unit tests and in the one-process
//! suite of `spacepose eval`.

use crate::config::ServiceConfig;
use crate::link::{LinkSpec, LinkStatus};
use spacepose_geometry::Point;
use spacepose_messages::{
    Cloud, CloudHeader, Counters, Message, Name, Names, ServiceKind, ServiceState, Topic,
};
use std::time::Duration;

/// Where a node's outputs go: publishers on the bus in a process, a queue
/// in a [`crate::LocalBus`].
pub trait Outbox {
    /// Publishes a fixed-size message on its topic.
    fn message(&mut self, msg: &Message) -> anyhow::Result<()>;
    /// Publishes a cloud on `topic`.
    fn cloud(&mut self, topic: Topic, header: CloudHeader, points: &[Point]) -> anyhow::Result<()>;
    /// Publishes JSON on the ground link under the telemetry key `key`
    /// (`spacepose/{prefix}/telemetry/{key}`).
    fn json(&mut self, key: &str, json: &str) -> anyhow::Result<()>;
}

/// What a node may do while it handles an input: send, count, read the
/// clock and its link's status.
pub struct Ctx<'a> {
    out: &'a mut dyn Outbox,
    /// Counters reported in the health heartbeat.
    pub counters: &'a mut Counters,
    /// CLOCK_REALTIME when the runtime woke up (ns since the Unix epoch);
    /// a [`crate::LocalBus`] sets it itself.
    pub now_ns: i64,
    /// The zenoh link's forwarding figures, for a node with a link.
    pub link: Option<&'a LinkStatus>,
}

impl<'a> Ctx<'a> {
    /// A context over `out` and `counters` at time `now_ns`.
    pub fn new(out: &'a mut dyn Outbox, counters: &'a mut Counters, now_ns: i64) -> Self {
        Ctx {
            out,
            counters,
            now_ns,
            link: None,
        }
    }

    /// Publishes `msg`; a failure is logged and counted in `errors`.
    /// Returns whether it went out.
    pub fn send(&mut self, msg: &Message) -> bool {
        let sent = self.out.message(msg);
        self.outcome(sent, msg.topic().as_str())
    }

    /// Publishes a cloud; a failure is logged and counted in `errors`.
    pub fn send_cloud(&mut self, topic: Topic, header: CloudHeader, points: &[Point]) -> bool {
        let sent = self.out.cloud(topic, header, points);
        self.outcome(sent, topic.as_str())
    }

    /// Publishes JSON on the ground link; a failure is logged and counted.
    pub fn send_json(&mut self, key: &str, json: &str) -> bool {
        let sent = self.out.json(key, json);
        self.outcome(sent, key)
    }

    fn outcome(&mut self, sent: anyhow::Result<()>, what: &str) -> bool {
        match sent {
            Ok(()) => true,
            Err(e) => {
                self.counters.errors += 1;
                tracing::warn!("publishing {what}: {e:#}");
                false
            }
        }
    }
}

/// Who a node is in its deployment.
#[derive(Debug, Clone)]
pub struct NodeInfo {
    /// The instance name (`--instance`, the config's `instance`, or the
    /// kind's name).
    pub instance: Name,
    /// The deployment's names.
    pub names: Names,
    /// The heartbeat period.
    pub heartbeat: Duration,
}

/// Whether the node goes on after a poll.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Flow {
    /// Keep running.
    Continue,
    /// The node's work is done (a sensor's last frame with `exit_at_end`):
    /// the runtime stops as on SIGTERM.
    Finished,
}

/// A service's logic, without any bus.
///
/// The runtime calls [`Node::on_message`] for every message of the kind's
/// input topics, in the order of [`ServiceKind::inputs`] (and again before
/// each cloud, so control sent before a cloud applies to it), then
/// [`Node::on_cloud`] per cloud, then [`Node::poll`] once per wake-up.
pub trait Node: Sized {
    /// Which service this is: its name, and its topics in the graph.
    const KIND: ServiceKind;
    /// The configuration file's contents.
    type Config: ServiceConfig;

    /// The zenoh link the node needs (ground telemetry, host bridge), from
    /// its configuration; none by default.
    ///
    /// # Errors
    /// A configuration that names unreadable files or bad routes.
    fn link(config: &Self::Config, names: &Names) -> anyhow::Result<Option<LinkSpec>> {
        let _ = (config, names);
        Ok(None)
    }

    /// Builds the node (models, methods, state) before the bus opens.
    ///
    /// # Errors
    /// Whatever keeps the service from starting; the process exits with it.
    fn new(config: Self::Config, info: &NodeInfo) -> anyhow::Result<Self>;

    /// A message of one of the kind's input topics.
    fn on_message(&mut self, msg: &Message, ctx: &mut Ctx<'_>) {
        let _ = (msg, ctx);
    }

    /// A cloud of one of the kind's input topics.
    fn on_cloud(&mut self, cloud: Cloud<'_>, ctx: &mut Ctx<'_>) {
        let _ = (cloud, ctx);
    }

    /// Called once per wake-up after the inputs: timers, deadlines, work
    /// finished on another thread.
    fn poll(&mut self, ctx: &mut Ctx<'_>) -> Flow {
        let _ = ctx;
        Flow::Continue
    }

    /// When the node next needs a [`Node::poll`] without an input
    /// (CLOCK_REALTIME, ns); `None`: at the next heartbeat.
    fn next_wake_ns(&self) -> Option<i64> {
        None
    }

    /// The state reported in the heartbeat.
    fn state(&self) -> ServiceState {
        ServiceState::Running
    }

    /// The JSON a `latest` query on the link answers with (telemetry).
    fn latest_json(&self) -> Option<String> {
        None
    }

    /// Called once on the way out, before the `Stopping` heartbeat.
    fn stop(&mut self, ctx: &mut Ctx<'_>) {
        let _ = ctx;
    }
}
