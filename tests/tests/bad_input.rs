//! Bad input driven through the bus into a running suite: a frame of NaN
//! points, a frame larger than the capacity, and garbage on the zenoh
//! command key. Each is logged and counted in health, nothing crashes, and
//! the frames that follow still get their pose. (An empty frame with a
//! valid header is not bad input: it is the observation "target not seen",
//! forwarded by ingest and answered `lost` by the tracker; see
//! `fuzz_input.rs` and `reacquire.rs`.)
#![allow(clippy::unwrap_used)] // test helpers

use spacepose_bus::zenoh::Wait;
use spacepose_bus::{Bus, ZenohConfig, open_zenoh};
use spacepose_e2e::*;
use spacepose_geometry::Point;
use spacepose_messages::{
    CloudHeader, Command, CommandKind, Health, MAX_POINTS, Name, Names, PoseEstimate, Topic, encode,
};
use std::collections::{BTreeMap, BTreeSet};
use std::time::{Duration, Instant};

const FRAMES: u64 = 24;

struct Watch {
    poses: spacepose_bus::Subscriber<PoseEstimate>,
    health: spacepose_bus::Subscriber<Health>,
    commands: spacepose_bus::Subscriber<Command>,
    seen: BTreeSet<u64>,
    latest: BTreeMap<String, Health>,
    commands_seen: Vec<Command>,
}

impl Watch {
    fn drain(&mut self) {
        while let Some(p) = self.poses.try_recv().unwrap() {
            self.seen.insert(p.sequence);
        }
        while let Some(h) = self.health.try_recv().unwrap() {
            self.latest.insert(h.instance.as_str().to_string(), h);
        }
        while let Some(c) = self.commands.try_recv().unwrap() {
            self.commands_seen.push(c);
        }
    }

    fn wait_until(&mut self, what: &str, timeout: Duration, mut done: impl FnMut(&Watch) -> bool) {
        let deadline = Instant::now() + timeout;
        loop {
            self.drain();
            if done(self) {
                return;
            }
            assert!(
                Instant::now() < deadline,
                "timed out waiting for {what}; poses {:?}",
                self.seen
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    fn health_of(&self, kind: &str) -> Health {
        *self
            .latest
            .values()
            .find(|h| h.service.as_str() == kind)
            .unwrap_or_else(|| panic!("no heartbeat from a {kind} service"))
    }
}

#[test]
fn bad_input_is_counted_and_the_next_frames_still_get_poses() {
    require_suite();
    let dir = scratch_dir("bad-input");
    let prefix = unique_prefix("bad");
    let _down = DownOnDrop(prefix.clone());
    let port = free_port();
    // A slower sensor leaves room between the frames for the bad ones.
    let deploy = demo_descriptor(&dir, FRAMES, 3.0);

    // Subscribe before the suite starts, so no pose is missed.
    let names = Names::new(&prefix).unwrap();
    let bus = Bus::open(&names, "e2e-bad-input").unwrap();
    let mut w = Watch {
        poses: bus.subscriber(&names.pose()).unwrap(),
        health: bus.subscriber(&names.health()).unwrap(),
        commands: bus.subscriber(&names.command()).unwrap(),
        seen: BTreeSet::new(),
        latest: BTreeMap::new(),
        commands_seen: Vec::new(),
    };
    let injector = bus
        .cloud_publisher(&names.raw_cloud(), MAX_POINTS + 1000)
        .unwrap();

    let endpoint = format!("tcp/127.0.0.1:{port}");
    let up = spacepose(&[
        "up",
        deploy.to_str().unwrap(),
        "--prefix",
        &prefix,
        "--listen",
        &endpoint,
    ]);
    assert!(up.status.success(), "{}", text(&up));

    w.wait_until("the first poses", Duration::from_secs(60), |w| {
        w.seen.len() >= 3
    });
    let bad_seq = 1_000_000;
    let nan = Point::new(f32::NAN, f32::NAN, f32::NAN, 0.0, 0.0);
    let header = |k: u64| CloudHeader::new(bad_seq + k, 0.0, 0.1);
    injector.send(header(0), &vec![nan; 500]).unwrap();
    std::thread::sleep(Duration::from_millis(150));
    let far = Point::new(0.0, 0.0, 15.0, 0.5, 0.05);
    injector
        .send(header(2), &vec![far; MAX_POINTS + 1])
        .unwrap();

    let injected_at = w.seen.iter().max().copied().unwrap_or(0);

    w.wait_until("the rejection counters", Duration::from_secs(30), |w| {
        let Some(ingest) = w.latest.values().find(|h| h.service.as_str() == "ingest") else {
            return false;
        };
        ingest.counters.rejected_non_finite >= 1 && ingest.counters.rejected_oversized >= 1
    });
    // Every frame after the injections still gets its pose, then all of them.
    w.wait_until("a pose for every frame", Duration::from_secs(90), |w| {
        w.seen.iter().filter(|s| **s < bad_seq).count() as u64 >= FRAMES
    });
    assert_eq!(
        w.seen
            .iter()
            .copied()
            .filter(|s| *s < bad_seq)
            .collect::<Vec<_>>(),
        (0..FRAMES).collect::<Vec<_>>()
    );
    assert!(
        w.seen.iter().all(|s| *s < bad_seq),
        "a bad frame produced a pose: {:?}",
        w.seen
    );
    assert!(
        injected_at + 1 < FRAMES,
        "the injections came too late to test the next frames"
    );

    // Nothing crashed: every instance still sends heartbeats from its pid.
    let status = spacepose(&["status", "--prefix", &prefix]);
    let status_text = text(&status);
    assert!(status.status.success(), "{status_text}");
    assert!(
        !status_text.contains(" no "),
        "an instance died:\n{status_text}"
    );
    assert!(!status_text.contains("no heartbeat"), "{status_text}");
    let ingest = w.health_of("ingest");
    println!(
        "ingest: non-finite {} oversized {}; status:\n{status_text}",
        ingest.counters.rejected_non_finite, ingest.counters.rejected_oversized
    );

    let down = spacepose(&["down", "--prefix", &prefix]);
    assert!(down.status.success(), "{}", text(&down));
    assert!(!state_file(&prefix).exists());
    assert!(processes_mentioning(&format!("--prefix {prefix}")).is_empty());
}

/// Garbage, then a valid command, on the zenoh command key of a running
/// suite (telemetry hosts the zenoh -> iceoryx2 command bridge): the garbage
/// is counted as `rejected_wire` in telemetry's health, the valid command
/// still reaches the iceoryx2 command topic, nothing crashes, and the next
/// frame still gets a pose.
#[test]
fn garbage_on_the_zenoh_command_key_is_counted_and_the_next_command_passes() {
    require_suite();
    let dir = scratch_dir("bad-command");
    let prefix = unique_prefix("cmd");
    let _down = DownOnDrop(prefix.clone());
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let deploy = demo_descriptor(&dir, 0, 2.0);
    let names = Names::new(&prefix).unwrap();
    let bus = Bus::open(&names, "e2e-bad-command").unwrap();
    let mut w = Watch {
        poses: bus.subscriber(&names.pose()).unwrap(),
        health: bus.subscriber(&names.health()).unwrap(),
        commands: bus.subscriber(&names.command()).unwrap(),
        seen: BTreeSet::new(),
        latest: BTreeMap::new(),
        commands_seen: Vec::new(),
    };
    let up = spacepose(&[
        "up",
        deploy.to_str().unwrap(),
        "--prefix",
        &prefix,
        "--listen",
        &endpoint,
    ]);
    assert!(up.status.success(), "{}", text(&up));
    w.wait_until("the first pose", Duration::from_secs(60), |w| {
        !w.seen.is_empty()
    });
    let session = open_zenoh(&ZenohConfig::client(&[endpoint.as_str()])).unwrap();
    let key = names.wire_key(Topic::Command);
    let mut cmd = Command::new(CommandKind::Mode, Name::new("e2e").unwrap());
    cmd.target_instance = Name::new("nobody").unwrap();
    cmd.sequence = 77;
    // A put sent before the client learns of the bridge's subscriber may be
    // dropped, so the pair is re-sent until both effects are seen.
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        session
            .put(&key, b"\x00garbage\xff not postcard".to_vec())
            .wait()
            .unwrap();
        session.put(&key, encode(&cmd).unwrap()).wait().unwrap();
        let until = Instant::now() + Duration::from_secs(2);
        while Instant::now() < until {
            w.drain();
            std::thread::sleep(Duration::from_millis(20));
        }
        let counted = w.health_of("telemetry").counters.rejected_wire >= 1;
        if counted && w.commands_seen.iter().any(|c| c.sequence == 77) {
            break;
        }
        assert!(
            Instant::now() < deadline,
            "timed out: telemetry rejected_wire {}, commands {:?}",
            w.health_of("telemetry").counters.rejected_wire,
            w.commands_seen
                .iter()
                .map(|c| c.sequence)
                .collect::<Vec<_>>()
        );
    }
    assert!(
        w.commands_seen.iter().all(|c| c.sequence == 77),
        "garbage reached the command topic: {:?}",
        w.commands_seen
    );

    // The next frame still gets a pose, and nothing crashed.
    let last = w.seen.iter().max().copied().unwrap_or(0);
    w.wait_until("a pose after the garbage", Duration::from_secs(30), |w| {
        w.seen.iter().any(|s| *s > last)
    });
    let status = spacepose(&["status", "--prefix", &prefix]);
    let status_text = text(&status);
    assert!(status.status.success(), "{status_text}");
    assert!(
        !status_text.contains(" no "),
        "an instance died:\n{status_text}"
    );
    assert!(!status_text.contains("no heartbeat"), "{status_text}");
    println!(
        "telemetry rejected_wire {}; status:\n{status_text}",
        w.health_of("telemetry").counters.rejected_wire
    );
}
