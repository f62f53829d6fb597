//! Tests of [`BridgeNode`] without processes: a `Ctx` over an outbox that
//! records what the node sends (nothing: its routes are the runtime's),
//! with the link's figures set by the test.

use super::*;
use crate::config::BridgeServiceConfig;
use spacepose_bus::{Direction, LinkLatency, Route};
use spacepose_geometry::Point;
use spacepose_messages::{CloudHeader, Message, Name, Topic};
use spacepose_runtime::Outbox;
use std::time::Duration;

const S: i64 = 1_000_000_000;
const T0: i64 = 1_700_000_000 * S;

/// Records every attempt to send.
#[derive(Default)]
struct Sent(Vec<String>);

impl Outbox for Sent {
    fn message(&mut self, msg: &Message) -> anyhow::Result<()> {
        self.0.push(format!("{:?}", msg.topic()));
        Ok(())
    }

    fn cloud(&mut self, topic: Topic, _: CloudHeader, _: &[Point]) -> anyhow::Result<()> {
        self.0.push(format!("{topic:?}"));
        Ok(())
    }

    fn json(&mut self, key: &str, _: &str) -> anyhow::Result<()> {
        self.0.push(key.to_string());
        Ok(())
    }
}

fn node(stats_file: Option<PathBuf>) -> BridgeNode {
    let config = BridgeServiceConfig {
        suite_prefix: "orbit".into(),
        stats_file,
        stats_period_s: 2.0,
        ..BridgeServiceConfig::default()
    };
    let info = NodeInfo {
        instance: Name::new("bridge").unwrap(),
        names: Names::new("host-b").unwrap(),
        heartbeat: Duration::from_millis(500),
    };
    BridgeNode::new(BridgeNodeConfig(config), &info).unwrap()
}

fn link() -> LinkStatus {
    LinkStatus {
        routes: vec![
            Route::from_zenoh(Topic::Cloud),
            Route::to_zenoh(Topic::Pose),
        ],
        latency: vec![(Topic::Cloud, LinkLatency::default())],
        running: true,
        ..LinkStatus::default()
    }
}

/// One wake-up (or the way out) at `now_ns`.
fn step(n: &mut BridgeNode, link: &LinkStatus, c: &mut Counters, now_ns: i64, stopping: bool) {
    let mut out = Sent::default();
    let mut ctx = Ctx::new(&mut out, c, now_ns);
    ctx.link = Some(link);
    if stopping {
        n.stop(&mut ctx);
    } else {
        assert_eq!(n.poll(&mut ctx), Flow::Continue);
    }
    assert!(out.0.is_empty(), "the node sent {:?}", out.0);
}

fn read(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn the_counters_follow_the_routes_and_keep_the_runtimes_own() {
    let mut n = node(None);
    let mut link = link();
    let mut c = Counters::default();
    step(&mut n, &link, &mut c, T0, false);
    assert_eq!(c, Counters::default());
    link.stats.forwarded_from_zenoh = 30;
    link.stats.forwarded_to_zenoh = 12;
    link.stats.rejected_wire = 1;
    link.stats.rate_limited = 5; // in the file only
    step(&mut n, &link, &mut c, T0 + S, false);
    assert_eq!(
        (c.frames_in, c.frames_out, c.rejected_wire, c.errors),
        (30, 12, 1, 0)
    );
    c.errors += 1; // e.g. a heartbeat the runtime could not publish
    link.stats.forwarded_from_zenoh = 31;
    link.stats.errors = 2;
    step(&mut n, &link, &mut c, T0 + 2 * S, false);
    step(&mut n, &link, &mut c, T0 + 3 * S, true);
    assert_eq!(
        (c.frames_in, c.frames_out, c.rejected_wire, c.errors),
        (31, 12, 1, 3)
    );
    assert_eq!(n.next_wake_ns(), None, "no stats_file: no timer");
}

#[test]
fn stopped_routes_degrade_the_state_and_no_route_is_no_stop() {
    let mut n = node(None);
    let mut link = link();
    let mut c = Counters::default();
    step(&mut n, &link, &mut c, T0, false);
    assert_eq!(n.state(), ServiceState::Running);
    link.running = false;
    step(&mut n, &link, &mut c, T0 + S, false);
    assert_eq!(n.state(), ServiceState::Degraded);
    let mut n = node(None);
    let idle = LinkStatus::default();
    step(&mut n, &idle, &mut c, T0, false);
    assert_eq!(n.state(), ServiceState::Running);
}

#[test]
fn the_stats_file_is_written_every_period_and_on_the_way_out() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bridge-b.stats.json");
    let mut n = node(Some(path.clone()));
    let mut link = link();
    let mut c = Counters::default();
    assert_eq!(n.next_wake_ns(), None);
    step(&mut n, &link, &mut c, T0, false);
    assert_eq!(n.next_wake_ns(), Some(T0 + 2 * S));
    step(&mut n, &link, &mut c, T0 + S, false);
    assert!(!path.exists(), "written before its period");
    link.stats.forwarded_from_zenoh = 4;
    link.latency[0].1 = LinkLatency {
        samples: 4,
        mean_ms: 0.5,
        max_ms: 0.9,
    };
    step(&mut n, &link, &mut c, T0 + 2 * S, false);
    let v = read(&path);
    assert_eq!(v["forwarded_from_zenoh"], 4);
    assert_eq!(v["latency_from_zenoh"]["cloud"]["samples"], 4);
    assert_eq!(
        v["routes"],
        serde_json::json!(["cloud FromZenoh", "pose ToZenoh"])
    );
    assert_eq!(n.next_wake_ns(), Some(T0 + 4 * S));
    link.stats.forwarded_from_zenoh = 9;
    step(&mut n, &link, &mut c, T0 + 3 * S, false);
    assert_eq!(read(&path)["forwarded_from_zenoh"], 4);
    step(&mut n, &link, &mut c, T0 + 3 * S, true);
    assert_eq!(read(&path)["forwarded_from_zenoh"], 9);
    assert_eq!(link.routes[1].direction, Direction::ToZenoh);
}

#[test]
fn without_a_link_the_node_does_nothing() {
    let mut bus = spacepose_runtime::LocalBus::new();
    let id = bus.add(node(None));
    bus.now_ns = T0;
    assert!(bus.poll().is_empty());
    assert_eq!(bus.counters(id), Some(&Counters::default()));
    assert_eq!(
        bus.node::<BridgeNode>(id).unwrap().state(),
        ServiceState::Running
    );
}

#[test]
fn the_link_is_the_configured_host_link() {
    let config: BridgeNodeConfig = toml::from_str(
        "suite_prefix = \"orbit\"\n[zenoh]\nconnect = [\"tcp/127.0.0.1:7450\"]\n\
         [[routes]]\ntopic = \"health\"\ndirection = \"to-zenoh\"\n",
    )
    .unwrap();
    let spec = BridgeNode::link(&config, &Names::new("host-a").unwrap())
        .unwrap()
        .unwrap();
    assert_eq!(spec.routes.len(), 1);
    assert_eq!(
        spec.routes[0].key.as_deref(),
        Some("spacepose/orbit/link/health")
    );
}
