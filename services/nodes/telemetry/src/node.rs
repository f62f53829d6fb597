//! The telemetry node: the suite's messages in, JSON on the ground link
//! out, the `latest` state for the queryable, and the command route's
//! figures in the health counters.

use crate::commands::CommandRoute;
use crate::config::{Rates, TelemetryNodeConfig};
use crate::error::TelemetryError;
use crate::hub::{Output, Stream, TelemetryHub};
use crate::link::link_spec;
use crate::rate::RateLimiter;
use spacepose_messages::{Message, Names, ServiceKind, Topic};
use spacepose_runtime::{Ctx, Flow, LinkSpec, Node, NodeInfo};

/// Turns poses, filter states, health and truth into rate-limited JSON.
pub struct TelemetryNode {
    hub: TelemetryHub,
    rates: Rates,
    limiter: RateLimiter,
    /// The `latest` state as JSON, as of the last poll.
    latest: String,
    /// Whether the hub changed since `latest` was written.
    latest_stale: bool,
    commands: CommandRoute,
}

impl Node for TelemetryNode {
    const KIND: ServiceKind = ServiceKind::Telemetry;
    type Config = TelemetryNodeConfig;

    fn link(config: &TelemetryNodeConfig, _: &Names) -> anyhow::Result<Option<LinkSpec>> {
        Ok(Some(link_spec(&config.0)))
    }

    fn new(config: TelemetryNodeConfig, info: &NodeInfo) -> anyhow::Result<Self> {
        let config = config.0;
        let hub = TelemetryHub::new(info.names.prefix(), config.match_window);
        tracing::info!(listen = ?config.zenoh.listen, connect = ?config.zenoh.connect, "ground link");
        Ok(TelemetryNode {
            latest: hub.latest_json()?,
            hub,
            rates: config.rates,
            limiter: RateLimiter::new(),
            latest_stale: false,
            commands: CommandRoute::new(info.names.wire_key(Topic::Command)),
        })
    }

    fn on_message(&mut self, msg: &Message, ctx: &mut Ctx<'_>) {
        let outputs = match msg {
            Message::Truth(m) => self.hub.on_truth(m),
            Message::Pose(m) => {
                ctx.counters.last_frame = m.sequence;
                self.hub.on_pose(m)
            }
            Message::FilterState(m) => self.hub.on_filter(m),
            Message::Health(m) => self.hub.on_health(m),
            _ => return,
        };
        ctx.counters.frames_in += 1;
        self.latest_stale = true;
        self.publish(outputs, ctx);
    }

    fn poll(&mut self, ctx: &mut Ctx<'_>) -> Flow {
        if self.latest_stale {
            self.latest_stale = false;
            match self.hub.latest_json() {
                Ok(json) => self.latest = json,
                Err(e) => {
                    ctx.counters.errors += 1;
                    tracing::warn!("the latest state: {e}");
                }
            }
        }
        if let Some(link) = ctx.link {
            self.commands.report(link, ctx.counters);
        }
        Flow::Continue
    }

    fn latest_json(&self) -> Option<String> {
        Some(self.latest.clone())
    }

    fn stop(&mut self, ctx: &mut Ctx<'_>) {
        if let Some(link) = ctx.link {
            self.commands.report(link, ctx.counters);
        }
    }
}

impl TelemetryNode {
    /// The hub (latest state, running figures).
    pub fn hub(&self) -> &TelemetryHub {
        &self.hub
    }

    /// Publishes what the hub made of a message within the rate limits; a
    /// message it refused is counted in `rejected_wire`.
    fn publish(&mut self, outputs: Result<Vec<Output>, TelemetryError>, ctx: &mut Ctx<'_>) {
        let outputs = match outputs {
            Ok(outputs) => outputs,
            Err(e) => {
                ctx.counters.rejected_wire += 1;
                tracing::warn!("message refused: {e}");
                return;
            }
        };
        for o in &outputs {
            let hz = rate_of(&self.rates, o.stream);
            if self.limiter.allow(&o.key, hz, ctx.now_ns) && ctx.send_json(&o.key, &o.json) {
                ctx.counters.frames_out += 1;
            }
        }
    }
}

/// The largest rate of a stream (Hz; 0 = every sample).
fn rate_of(rates: &Rates, stream: Stream) -> f64 {
    match stream {
        Stream::Pose => rates.pose_hz,
        Stream::Filter => rates.filter_hz,
        Stream::Health => rates.health_hz,
        Stream::Truth => rates.truth_hz,
        Stream::Errors => rates.errors_hz,
    }
}

#[cfg(test)]
#[path = "node_tests.rs"]
mod tests;
