//! Process-level test: the real `spacepose-recorder` binary on a private
//! prefix. It also makes `cargo test --workspace` build the binary, which
//! the suite's end-to-end tests (`tests/`) start.
#![allow(clippy::unwrap_used)] // tests may unwrap

use spacepose_bus::{Bus, Subscriber};
use spacepose_messages::{Health, Names, PoseEstimate, ServiceState, WireStatus};
use spacepose_runtime::testing::{ChildGuard, unique_prefix, wait_for};
use std::process::{Command, Stdio};
use std::time::Duration;

fn recorder() -> Command {
    Command::new(env!("CARGO_BIN_EXE_spacepose-recorder"))
}

#[test]
fn a_config_without_file_or_live_view_is_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("recorder.toml");
    std::fs::write(&config, "compression = \"lz4\"\n").unwrap();
    let out = recorder()
        .args(["--check", "--config"])
        .arg(&config)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.contains("file"), "{stderr}");
    // The same file with a destination passes the check.
    std::fs::write(
        &config,
        format!("file = {:?}\n", dir.path().join("run.mcap")),
    )
    .unwrap();
    let ok = recorder()
        .args(["--check", "--config"])
        .arg(&config)
        .output()
        .unwrap();
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
}

#[test]
fn a_recording_stopped_by_sigterm_is_a_closed_mcap_file_with_every_pose() {
    let prefix = unique_prefix("trec");
    let names = Names::new(&prefix).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("run.mcap");
    let config = dir.path().join("recorder.toml");
    std::fs::write(&config, format!("file = {file:?}\ntarget = \"\"\n")).unwrap();

    let bus = Bus::open(&names, "test").unwrap();
    let health = bus.subscriber::<Health>(&names.health()).unwrap();
    let poses = bus.publisher::<PoseEstimate>(&names.pose()).unwrap();
    let mut service = ChildGuard(
        recorder()
            .args(["--prefix", &prefix, "--heartbeat-ms", "50", "--config"])
            .arg(&config)
            .stdout(Stdio::null())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap(),
    );
    heartbeat(&health, "running", |h| {
        h.state == ServiceState::Running as u8
    });
    for seq in 1..=3u64 {
        let mut e = PoseEstimate::new();
        e.sequence = seq;
        e.t_s = seq as f64;
        e.status = WireStatus::Tracking as u8;
        e.p_sensor_target = [0.0, 0.0, 12.0];
        poses.send(&e).unwrap();
    }
    heartbeat(&health, "three frames in", |h| h.counters.frames_in >= 3);

    let status = service.terminate(Duration::from_secs(10));
    assert!(status.success(), "{status:?}");
    let bytes = std::fs::read(&file).unwrap();
    mcap::Summary::read(&bytes)
        .unwrap()
        .expect("closed: a summary");
    let recorded = mcap::MessageStream::new(&bytes)
        .unwrap()
        .filter(|m| m.as_ref().unwrap().channel.topic == "/spacepose/pose")
        .count();
    assert_eq!(recorded, 3);
}

/// The recorder's first heartbeat that `accept`s (20 s at most).
fn heartbeat(health: &Subscriber<Health>, what: &str, accept: impl Fn(&Health) -> bool) -> Health {
    wait_for(what, Duration::from_secs(20), || {
        std::iter::from_fn(|| health.try_recv().unwrap())
            .find(|h| h.instance.as_str() == "recorder" && accept(h))
    })
}
