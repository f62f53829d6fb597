//! Tests of [`TelemetryNode`] without processes: on a `LocalBus`, and
//! through a `Ctx` over a small outbox for the link's figures.

use super::*;
use crate::config::TelemetryConfig;
use spacepose_geometry::Point;
use spacepose_messages::{
    CloudHeader, Counters, FilterState, Health, Name, PoseEstimate, ServiceState, TruthMsg,
    WireStatus,
};
use spacepose_runtime::{Envelope, LinkStatus, LocalBus, Outbox};
use std::time::Duration;

const MS: i64 = 1_000_000;
const T0: i64 = 1_700_000_000_000 * MS;

fn node(rates: Rates) -> TelemetryNode {
    let info = NodeInfo {
        instance: Name::new("telemetry").unwrap(),
        names: Names::new("tnode").unwrap(),
        heartbeat: Duration::from_millis(500),
    };
    let config = TelemetryConfig {
        rates,
        ..TelemetryConfig::default()
    };
    TelemetryNode::new(TelemetryNodeConfig(config), &info).unwrap()
}

fn every_sample() -> Rates {
    Rates {
        pose_hz: 0.0,
        filter_hz: 0.0,
        health_hz: 0.0,
        truth_hz: 0.0,
        errors_hz: 0.0,
    }
}

fn estimate(seq: u64) -> PoseEstimate {
    let mut e = PoseEstimate::new();
    e.sequence = seq;
    e.t_s = seq as f64;
    e.status = WireStatus::Tracking as u8;
    e.instance = Name::new("tracker-t").unwrap();
    e.p_sensor_target = [0.0, 0.0, 12.0];
    e
}

fn truth(seq: u64) -> TruthMsg {
    let mut t = TruthMsg::new();
    t.sequence = seq;
    t.p_sensor_target = [0.0, 0.0, 12.05];
    t
}

fn health(instance: &str) -> Health {
    let mut h = Health::new(Name::new("x").unwrap(), Name::new(instance).unwrap(), 7);
    h.state = ServiceState::Running as u8;
    h
}

/// The JSON keys sent, in order.
fn keys(sent: &[Envelope]) -> Vec<&str> {
    sent.iter()
        .filter_map(|e| match e {
            Envelope::Json { key, .. } => Some(key.as_str()),
            _ => None,
        })
        .collect()
}

fn json(sent: &[Envelope], wanted: &str) -> serde_json::Value {
    sent.iter()
        .find_map(|e| match e {
            Envelope::Json { key, json } if key == wanted => {
                Some(serde_json::from_str(json).unwrap())
            }
            _ => None,
        })
        .unwrap_or_else(|| panic!("no {wanted} in {sent:?}"))
}

#[test]
fn truth_and_poses_become_json_counters_and_the_latest_state() {
    let mut bus = LocalBus::new();
    let id = bus.add(node(every_sample()));
    bus.now_ns = T0;
    bus.publish(Message::Truth(truth(4)));
    bus.publish(Message::Pose(estimate(4)));
    bus.publish(Message::Health(health("tracker-t")));
    let sent = bus.run();
    assert_eq!(keys(&sent), ["truth", "pose", "errors", "health/tracker-t"]);
    let errors = json(&sent, "errors");
    assert!(
        (errors["pos_err_cm"].as_f64().unwrap() - 5.0).abs() < 1e-6,
        "{errors}"
    );
    assert_eq!(json(&sent, "pose")["instance"], "tracker-t");
    let c = bus.counters(id).unwrap();
    assert_eq!((c.frames_in, c.frames_out, c.last_frame), (3, 4, 4));
    assert_eq!((c.rejected_wire, c.errors), (0, 0));
    // The queryable's answer follows the messages (written at the poll).
    let n = bus.node::<TelemetryNode>(id).unwrap();
    let latest: serde_json::Value = serde_json::from_str(&n.latest_json().unwrap()).unwrap();
    assert_eq!(latest["prefix"], "tnode");
    assert_eq!(latest["pose"]["sequence"], 4);
    assert_eq!(latest["frames"]["scored"], 1);
    assert_eq!(latest["health"]["tracker-t"]["pid"], 7);
}

#[test]
fn streams_are_rate_limited_per_key_but_latest_sees_everything() {
    let mut bus = LocalBus::new();
    let id = bus.add(node(Rates::default())); // filter 10 Hz, health 2 Hz per instance
    let mut filter = FilterState::new();
    filter.initialized = 1;
    for (at_ms, sequence) in [(0, 1), (50, 2), (99, 3), (100, 4), (150, 5)] {
        bus.now_ns = T0 + at_ms * MS;
        filter.sequence = sequence;
        bus.publish(Message::FilterState(filter));
        bus.publish(Message::Health(health("filter")));
        bus.publish(Message::Health(health("tracker-a")));
        let sent = bus.run();
        let expected: &[&str] = match at_ms {
            0 => &["filter", "health/filter", "health/tracker-a"],
            100 => &["filter"],
            _ => &[],
        };
        assert_eq!(keys(&sent), expected, "at {at_ms} ms");
    }
    let c = bus.counters(id).unwrap();
    assert_eq!((c.frames_in, c.frames_out), (15, 4));
    let n = bus.node::<TelemetryNode>(id).unwrap();
    let latest: serde_json::Value = serde_json::from_str(&n.latest_json().unwrap()).unwrap();
    assert_eq!(latest["filter"]["sequence"], 5);
}

#[test]
fn refused_messages_are_counted_and_publish_nothing() {
    let mut bus = LocalBus::new();
    let id = bus.add(node(every_sample()));
    let mut bad = estimate(9);
    bad.status = 7;
    bus.publish(Message::Pose(bad));
    let mut t = truth(9);
    t.q_sensor_target = [0.0; 4];
    bus.publish(Message::Truth(t));
    assert!(keys(&bus.run()).is_empty());
    let c = bus.counters(id).unwrap();
    assert_eq!(
        (c.frames_in, c.frames_out, c.rejected_wire, c.last_frame),
        (2, 0, 2, 9)
    );
    assert_eq!(
        bus.node::<TelemetryNode>(id)
            .unwrap()
            .hub()
            .latest()
            .frames
            .poses,
        0
    );
}

/// An outbox whose ground link fails on `key`, and keeps the rest.
#[derive(Default)]
struct Ground {
    failing: Option<&'static str>,
    sent: Vec<String>,
}

impl Outbox for Ground {
    fn message(&mut self, msg: &Message) -> anyhow::Result<()> {
        anyhow::bail!("{:?} is not an output here", msg.topic())
    }

    fn cloud(&mut self, topic: Topic, _: CloudHeader, _: &[Point]) -> anyhow::Result<()> {
        anyhow::bail!("{topic:?} is not an output here")
    }

    fn json(&mut self, key: &str, _: &str) -> anyhow::Result<()> {
        if self.failing == Some(key) {
            anyhow::bail!("the link is down");
        }
        self.sent.push(key.to_string());
        Ok(())
    }
}

#[test]
fn failed_publications_are_errors_not_outputs() {
    let mut n = node(every_sample());
    let mut out = Ground {
        failing: Some("errors"),
        ..Ground::default()
    };
    let mut counters = Counters::default();
    let mut ctx = Ctx::new(&mut out, &mut counters, T0);
    n.on_message(&Message::Truth(truth(1)), &mut ctx);
    n.on_message(&Message::Pose(estimate(1)), &mut ctx);
    assert_eq!(
        (counters.frames_in, counters.frames_out, counters.errors),
        (2, 2, 1)
    );
    assert_eq!(out.sent, ["truth", "pose"]);
}

#[test]
fn the_command_route_adds_its_rejections_and_its_stop_once() {
    let mut n = node(every_sample());
    let mut out = Ground::default();
    let mut counters = Counters::default();
    let mut status = LinkStatus {
        running: true,
        ..LinkStatus::default()
    };
    let mut step = |status: &LinkStatus, counters: &mut Counters, stopping: bool| {
        let mut ctx = Ctx::new(&mut out, counters, T0);
        ctx.link = Some(status);
        if stopping {
            n.stop(&mut ctx);
        } else {
            assert_eq!(n.poll(&mut ctx), Flow::Continue);
        }
    };
    step(&status, &mut counters, false);
    assert_eq!((counters.rejected_wire, counters.errors), (0, 0));
    status.stats.rejected_wire = 4;
    step(&status, &mut counters, false);
    step(&status, &mut counters, false);
    assert_eq!((counters.rejected_wire, counters.errors), (4, 0));
    status.running = false;
    status.stats.rejected_wire = 5;
    step(&status, &mut counters, false);
    step(&status, &mut counters, true);
    assert_eq!((counters.rejected_wire, counters.errors), (5, 1));
}

#[test]
fn the_link_is_the_ground_link() {
    let config = TelemetryNodeConfig::default();
    let spec = TelemetryNode::link(&config, &Names::new("tnode").unwrap())
        .unwrap()
        .unwrap();
    assert_eq!(spec.latest_key.as_deref(), Some(crate::LATEST_KEY));
    assert_eq!(spec.routes.len(), 1);
    assert_eq!(spec.routes[0].topic, Topic::Command);
}
