//! Process-level test: the real `spacepose-telemetry` binary on a private
//! prefix and port, read over zenoh like a ground tool.
#![allow(clippy::unwrap_used)] // tests may unwrap

use spacepose_bus::zenoh::Wait;
use spacepose_bus::{Bus, ZenohConfig, open_zenoh};
use spacepose_messages::telemetry::TelemetryPose;
use spacepose_messages::{Health, Name, Names, PoseEstimate, ServiceState, TruthMsg, WireStatus};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Kills the service if the test fails before stopping it.
struct Service(Child);

impl Drop for Service {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn prefix() -> String {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .subsec_nanos();
    format!("ttel{}x{}", std::process::id(), nanos % 1_000_000)
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

fn wait_for<T>(mut recv: impl FnMut() -> Option<T>, mut accept: impl FnMut(&T) -> bool) -> T {
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        while let Some(m) = recv() {
            if accept(&m) {
                return m;
            }
        }
        assert!(Instant::now() < deadline, "timed out");
        std::thread::sleep(Duration::from_millis(10));
    }
}

fn estimate(seq: u64) -> PoseEstimate {
    let mut e = PoseEstimate::new();
    e.sequence = seq;
    e.t_s = seq as f64;
    e.status = WireStatus::Tracking as u8;
    e.instance = Name::new("tracker-t").unwrap();
    e.p_sensor_target = [0.0, 0.0, 12.0];
    e.cloud_published_ns = spacepose_messages::realtime_ns();
    e
}

#[test]
fn telemetry_republishes_poses_as_json_and_answers_latest() {
    let prefix = prefix();
    let names = Names::new(&prefix).unwrap();
    let port = free_port();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let dir = std::env::temp_dir().join(format!("{prefix}.toml"));
    std::fs::write(&dir, format!("[zenoh]\nlisten = [\"{endpoint}\"]\n")).unwrap();

    let bus = Bus::open(&names, "test").unwrap();
    let health = bus.subscriber::<Health>(&names.health()).unwrap();
    let poses = bus.publisher::<PoseEstimate>(&names.pose()).unwrap();
    let truth = bus.publisher::<TruthMsg>(&names.truth()).unwrap();
    let mut service = Service(
        Command::new(env!("CARGO_BIN_EXE_spacepose-telemetry"))
            .args(["--prefix", &prefix, "--heartbeat-ms", "50", "--config"])
            .arg(&dir)
            .stdout(Stdio::null())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap(),
    );
    wait_for(
        || health.try_recv().unwrap(),
        |h| h.instance.as_str() == "telemetry",
    );
    std::fs::remove_file(&dir).unwrap();

    // A ground client: subscribe to the pose and errors keys.
    let session = open_zenoh(&ZenohConfig::client(&[&endpoint])).unwrap();
    let (tx, rx) = mpsc::channel::<(String, String)>();
    let _sub = session
        .declare_subscriber(names.telemetry_key("**"))
        .callback(move |s| {
            let text = String::from_utf8(s.payload().to_bytes().to_vec()).unwrap();
            let _ = tx.send((s.key_expr().as_str().to_string(), text));
        })
        .wait()
        .unwrap();
    std::thread::sleep(Duration::from_millis(300));

    // Publish poses until the first arrives (the subscription propagates asynchronously).
    let pose_key = names.telemetry_key("pose");
    let mut seq = 0;
    let got = wait_for(
        || {
            seq += 1;
            let mut t = TruthMsg::new();
            t.sequence = seq;
            t.p_sensor_target = [0.0, 0.0, 12.05];
            truth.send(&t).unwrap();
            poses.send(&estimate(seq)).unwrap();
            rx.recv_timeout(Duration::from_millis(100)).ok()
        },
        |(key, _)| *key == pose_key,
    );
    let pose: TelemetryPose = serde_json::from_str(&got.1).unwrap();
    assert_eq!(
        (pose.instance.as_str(), pose.status.as_str()),
        ("tracker-t", "tracking")
    );
    assert_eq!(pose.p_sensor_target_m, [0.0, 0.0, 12.0]);
    assert!(pose.latency_ms.unwrap() >= 0.0);
    let errors_key = names.telemetry_key("errors");
    let (_, errors) = wait_for(
        || rx.recv_timeout(Duration::from_millis(100)).ok(),
        |(k, _)| *k == errors_key,
    );
    let errors: serde_json::Value = serde_json::from_str(&errors).unwrap();
    assert!(
        (errors["pos_err_cm"].as_f64().unwrap() - 5.0).abs() < 1e-6,
        "{errors}"
    );

    // The queryable returns the latest state as one JSON object.
    let replies = session
        .get(names.telemetry_key("latest"))
        .timeout(Duration::from_secs(5))
        .wait()
        .unwrap();
    let reply = replies
        .recv_timeout(Duration::from_secs(5))
        .unwrap()
        .unwrap();
    let sample = reply.result().unwrap();
    let latest: serde_json::Value = serde_json::from_slice(&sample.payload().to_bytes()).unwrap();
    assert_eq!(latest["prefix"], prefix.as_str());
    assert_eq!(latest["pose"]["instance"], "tracker-t");
    assert!(latest["frames"]["poses"].as_u64().unwrap() >= 1);
    assert!(latest["health"]["telemetry"]["pid"].as_u64().unwrap() > 0);

    let pid = service.0.id().to_string();
    assert!(
        Command::new("kill")
            .args(["-TERM", &pid])
            .status()
            .unwrap()
            .success()
    );
    let deadline = Instant::now() + Duration::from_secs(5);
    let status = loop {
        if let Some(s) = service.0.try_wait().unwrap() {
            break s;
        }
        assert!(Instant::now() < deadline, "no exit after SIGTERM");
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(status.success());
    wait_for(
        || health.try_recv().unwrap(),
        |h| h.state == ServiceState::Stopping as u8,
    );
}

/// Starts the service listening on `endpoint` with `prefix`.
fn start(prefix: &str, endpoint: &str) -> Service {
    let config = std::env::temp_dir().join(format!("{prefix}.toml"));
    std::fs::write(&config, format!("[zenoh]\nlisten = [\"{endpoint}\"]\n")).unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_spacepose-telemetry"))
        .args(["--prefix", prefix, "--heartbeat-ms", "50", "--config"])
        .arg(&config)
        .stdout(Stdio::null())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    Service(child)
}

#[test]
fn commands_from_zenoh_reach_the_bus_and_garbage_is_counted() {
    use spacepose_bus::zenoh::qos::CongestionControl;
    use spacepose_messages::{Command as SuiteCommand, CommandKind, Topic, encode};

    let prefix = prefix();
    let names = Names::new(&prefix).unwrap();
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let bus = Bus::open(&names, "test").unwrap();
    let health = bus.subscriber::<Health>(&names.health()).unwrap();
    let commands = bus.subscriber::<SuiteCommand>(&names.command()).unwrap();
    let _service = start(&prefix, &endpoint);
    wait_for(
        || health.try_recv().unwrap(),
        |h| h.instance.as_str() == "telemetry",
    );
    std::fs::remove_file(std::env::temp_dir().join(format!("{prefix}.toml"))).unwrap();

    let session = open_zenoh(&ZenohConfig::client(&[&endpoint])).unwrap();
    let publisher = session
        .declare_publisher(names.wire_key(Topic::Command))
        .congestion_control(CongestionControl::Block)
        .wait()
        .unwrap();
    let mut command = SuiteCommand::new(CommandKind::Reinit, Name::new("ops").unwrap());
    // The route is up once a command comes through.
    let got = wait_for(
        || {
            command.sequence += 1;
            publisher.put(encode(&command).unwrap()).wait().unwrap();
            std::thread::sleep(Duration::from_millis(50));
            commands.try_recv().unwrap()
        },
        |c| c.kind == CommandKind::Reinit as u8,
    );
    assert_eq!(got.issued_by.as_str(), "ops");
    for garbage in [&b"not a command"[..], &[0x53, 0x50, 0xff, 0xff, 7][..]] {
        publisher.put(garbage.to_vec()).wait().unwrap();
    }
    let beat = wait_for(
        || health.try_recv().unwrap(),
        |h| h.instance.as_str() == "telemetry" && h.counters.rejected_wire >= 2,
    );
    assert_eq!((beat.counters.rejected_wire, beat.counters.errors), (2, 0));
}
