//! zenoh: two peer sessions on distinct loopback ports, pub/sub in the codec.

#![allow(clippy::unwrap_used)] // tests may unwrap

mod common;

use common::{free_port, unique_names};
use spacepose_bus::{ZenohConfig, open_zenoh};
use spacepose_messages::{PoseEstimate, decode, encode};
use std::time::{Duration, Instant};
use zenoh::Wait;

#[test]
fn config_is_peer_loopback_without_multicast() {
    let c = ZenohConfig::default();
    assert_eq!(c.mode, "peer");
    assert_eq!(c.listen, vec!["tcp/127.0.0.1:7447".to_string()]);
    assert!(c.connect.is_empty());
    assert!(!c.multicast_scouting);
    assert!(c.to_zenoh().is_ok());
    let bad = ZenohConfig {
        mode: "router-ish".into(),
        ..ZenohConfig::default()
    };
    assert!(bad.to_zenoh().is_err());
    let bad_endpoint = ZenohConfig {
        listen: vec!["not an endpoint".into()],
        ..ZenohConfig::default()
    };
    assert!(open_zenoh(&bad_endpoint).is_err());
}

#[test]
fn two_peers_exchange_a_pose_on_loopback() {
    let names = unique_names("zenoh");
    let port_a = free_port();
    let port_b = free_port();
    let a = open_zenoh(&ZenohConfig::loopback(port_a)).unwrap();
    let b =
        open_zenoh(&ZenohConfig::loopback(port_b).connect_to(&format!("tcp/127.0.0.1:{port_a}")))
            .unwrap();
    let key = names.telemetry_key("test");
    let sub = b.declare_subscriber(&key).wait().unwrap();
    let publisher = a.declare_publisher(key.clone()).wait().unwrap();
    let mut sent = PoseEstimate::new();
    sent.sequence = 99;
    let bytes = encode(&sent).unwrap();
    let deadline = Instant::now() + Duration::from_secs(10);
    let received = loop {
        assert!(Instant::now() < deadline, "no sample within 10 s");
        publisher.put(bytes.clone()).wait().unwrap();
        if let Some(sample) = sub.recv_timeout(Duration::from_millis(100)).unwrap() {
            break sample.payload().to_bytes().into_owned();
        }
    };
    let got: PoseEstimate = decode(&received).unwrap();
    assert_eq!(got, sent);
    a.close().wait().unwrap();
    b.close().wait().unwrap();
}
