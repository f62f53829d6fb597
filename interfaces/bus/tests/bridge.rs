//! The bridge: PoseEstimate iceoryx2 -> zenoh, Command zenoh -> iceoryx2,
//! garbage counted and survived, clouds rate limited.

#![allow(clippy::unwrap_used)] // tests may unwrap

mod common;

use common::{free_port, unique_names};
use spacepose_bus::{Bridge, BridgeStats, Bus, Route, WakeReason, ZenohConfig, open_zenoh};
use spacepose_geometry::Point;
use spacepose_messages::{
    CloudHeader, CloudMsg, Command, CommandKind, Name, PoseEstimate, SCHEMA_VERSION, Topic, decode,
    encode,
};
use std::time::{Duration, Instant};
use zenoh::Wait;

/// A bridge session and a "ground" session linked on loopback.
fn sessions() -> (zenoh::Session, zenoh::Session) {
    let port = free_port();
    let bridge = open_zenoh(&ZenohConfig::loopback(port)).unwrap();
    let ground = open_zenoh(&ZenohConfig::client(&[&format!("tcp/127.0.0.1:{port}")])).unwrap();
    (bridge, ground)
}

#[test]
fn pose_goes_out_command_comes_in_and_garbage_is_counted() {
    let names = unique_names("bridge");
    let (bridge_session, ground) = sessions();
    let bridge = Bridge::start(
        &names,
        &bridge_session,
        &[
            Route::to_zenoh(Topic::Pose),
            Route::from_zenoh(Topic::Command),
        ],
    )
    .unwrap();
    let bus = Bus::open(&names, "test").unwrap();

    // iceoryx2 -> zenoh
    let pose_out = bus.publisher::<PoseEstimate>(&names.pose()).unwrap();
    let pose_in = ground
        .declare_subscriber(names.wire_key(Topic::Pose))
        .wait()
        .unwrap();
    let mut pose = PoseEstimate::new();
    pose.sequence = 7;
    pose.instance = Name::new("tracker-a").unwrap();
    let deadline = Instant::now() + Duration::from_secs(10);
    let got = loop {
        assert!(Instant::now() < deadline, "no pose on zenoh within 10 s");
        pose_out.send(&pose).unwrap();
        if let Some(s) = pose_in.recv_timeout(Duration::from_millis(100)).unwrap() {
            break decode::<PoseEstimate>(&s.payload().to_bytes()).unwrap();
        }
    };
    assert_eq!((got.sequence, got.instance.as_str()), (7, "tracker-a"));
    assert!(got.published_ns > 0);

    // zenoh -> iceoryx2, with garbage before every valid command
    let commands = bus.subscriber::<Command>(&names.command()).unwrap();
    let mut waiter = bus.waitset_without_signals().unwrap();
    waiter.attach(&commands).unwrap();
    let command_out = ground
        .declare_publisher(names.wire_key(Topic::Command))
        .wait()
        .unwrap();
    let mut command = Command::new(CommandKind::Reinit, Name::new("ground").unwrap());
    command.sequence = 3;
    let valid = encode(&command).unwrap();
    let mut future_version = valid.clone();
    future_version[2..4].copy_from_slice(&(SCHEMA_VERSION + 1).to_le_bytes());
    let wrong_kind = encode(&pose).unwrap();
    let deadline = Instant::now() + Duration::from_secs(10);
    let received = loop {
        assert!(
            Instant::now() < deadline,
            "no command on iceoryx2 within 10 s"
        );
        for garbage in [&b"garbage"[..], &[][..], &future_version, &wrong_kind] {
            command_out.put(garbage.to_vec()).wait().unwrap();
        }
        command_out.put(valid.clone()).wait().unwrap();
        if waiter.wait(Duration::from_millis(200)).unwrap() == WakeReason::Notified
            && let Some(c) = commands.try_recv().unwrap()
        {
            break c;
        }
    };
    assert_eq!(
        (received.sequence, received.kind),
        (3, CommandKind::Reinit as u8)
    );
    assert_eq!(received.issued_by.as_str(), "ground");
    // Garbage published before the valid command was handled first (one channel).
    // The bridge counts a forwarded sample just after publishing it, so the
    // counter may trail the received command by a moment: wait for it.
    let deadline = std::time::Instant::now() + Duration::from_secs(5);
    let mut stats = bridge.stats();
    while stats.forwarded_from_zenoh == 0 && std::time::Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(5));
        stats = bridge.stats();
    }
    assert!(stats.rejected_wire >= 4, "{stats:?}");
    assert!(stats.forwarded_from_zenoh >= 1, "{stats:?}");
    assert!(stats.forwarded_to_zenoh >= 1, "{stats:?}");
    assert!(bridge.is_running());
    bridge.stop().unwrap();
}

#[test]
fn clouds_are_rate_limited() {
    let names = unique_names("bridge-cloud");
    let (bridge_session, ground) = sessions();
    let bridge = Bridge::start(
        &names,
        &bridge_session,
        &[Route::to_zenoh(Topic::Cloud).with_rate(Some(2.0))],
    )
    .unwrap();
    let bus = Bus::open(&names, "test").unwrap();
    let clouds = bus.cloud_publisher(&names.cloud(), 10_000).unwrap();
    let cloud_in = ground
        .declare_subscriber(names.wire_key(Topic::Cloud))
        .wait()
        .unwrap();
    let points: Vec<Point> = (0..5000)
        .map(|i| Point::new(i as f32, 0.0, 1.0, 0.5, 0.0))
        .collect();
    // Wait until the link carries a first frame.
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut warm_up_sent = 0;
    let first = loop {
        assert!(Instant::now() < deadline, "no cloud on zenoh within 10 s");
        clouds.send(CloudHeader::new(0, 0.0, 0.1), &points).unwrap();
        warm_up_sent += 1;
        if let Some(s) = cloud_in.recv_timeout(Duration::from_millis(600)).unwrap() {
            break decode::<CloudMsg>(&s.payload().to_bytes()).unwrap();
        }
    };
    assert_eq!(first.points, points);
    // Let the worker account for the warm-up frames it will see (a late one
    // would otherwise count among the 20 below): wait until its counts have
    // stood still for 300 ms. Frames sent before it subscribed never come.
    let total = |s: &BridgeStats| s.forwarded_to_zenoh + s.rate_limited + s.errors;
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut before = bridge.stats();
    let mut still_since = Instant::now();
    while total(&before) < warm_up_sent && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(20));
        let now = bridge.stats();
        if total(&now) != total(&before) {
            still_since = Instant::now();
        } else if still_since.elapsed() > Duration::from_millis(300) {
            break;
        }
        before = now;
    }
    // 20 frames at ~50 Hz for 0.4 s: a 2 Hz limit lets at most 2 through.
    for seq in 1..=20 {
        clouds
            .send(CloudHeader::new(seq, 0.0, 0.1), &points)
            .unwrap();
        std::thread::sleep(Duration::from_millis(20));
    }
    // Every frame is either forwarded or dropped by the limiter; wait for the
    // worker to have seen all 20 (it may lag on a loaded machine).
    let deadline = Instant::now() + Duration::from_secs(10);
    let (after, forwarded, limited) = loop {
        let after = bridge.stats();
        let forwarded = after.forwarded_to_zenoh - before.forwarded_to_zenoh;
        let limited = after.rate_limited - before.rate_limited;
        if forwarded + limited >= 20 || Instant::now() > deadline {
            break (after, forwarded, limited);
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(forwarded <= 2, "{after:?}");
    assert_eq!(forwarded + limited, 20, "{after:?}");
    drop(bridge); // stops and joins on drop
}

#[test]
fn a_topic_in_both_directions_is_refused() {
    let names = unique_names("bridge-cfg");
    let (bridge_session, _ground) = sessions();
    let err = Bridge::start(
        &names,
        &bridge_session,
        &[
            Route::to_zenoh(Topic::Command),
            Route::from_zenoh(Topic::Command),
        ],
    )
    .unwrap_err();
    assert!(err.to_string().contains("command"), "{err}");
}
