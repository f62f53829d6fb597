//! Process-level test: the real `spacepose-recorder` binary on a private
//! prefix. It also makes `cargo test --workspace` build the binary, which
//! the suite's end-to-end tests (`tests/`) start.
#![allow(clippy::unwrap_used)] // tests may unwrap

use spacepose_bus::Bus;
use spacepose_messages::{Health, Names, PoseEstimate, ServiceState, WireStatus};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// MCAP's magic, at the start and at the end of a closed file.
const MAGIC: &[u8] = b"\x89MCAP0\r\n";

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
    format!("trec{}x{}", std::process::id(), nanos % 1_000_000)
}

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
fn a_recording_stopped_by_sigterm_is_a_closed_mcap_file() {
    let prefix = prefix();
    let names = Names::new(&prefix).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("run.mcap");
    let config = dir.path().join("recorder.toml");
    std::fs::write(&config, format!("file = {file:?}\ntarget = \"\"\n")).unwrap();

    let bus = Bus::open(&names, "test").unwrap();
    let health = bus.subscriber::<Health>(&names.health()).unwrap();
    let poses = bus.publisher::<PoseEstimate>(&names.pose()).unwrap();
    let mut service = Service(
        recorder()
            .args(["--prefix", &prefix, "--heartbeat-ms", "50", "--config"])
            .arg(&config)
            .stdout(Stdio::null())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap(),
    );
    wait_health(&health, ServiceState::Running);
    for seq in 1..=3u64 {
        let mut e = PoseEstimate::new();
        e.sequence = seq;
        e.t_s = seq as f64;
        e.status = WireStatus::Tracking as u8;
        e.p_sensor_target = [0.0, 0.0, 12.0];
        poses.send(&e).unwrap();
        std::thread::sleep(Duration::from_millis(50));
    }
    std::thread::sleep(Duration::from_millis(300));

    let pid = service.0.id().to_string();
    assert!(
        Command::new("kill")
            .args(["-TERM", &pid])
            .status()
            .unwrap()
            .success()
    );
    let deadline = Instant::now() + Duration::from_secs(10);
    let status = loop {
        if let Some(s) = service.0.try_wait().unwrap() {
            break s;
        }
        assert!(Instant::now() < deadline, "no exit after SIGTERM");
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(status.success());
    let bytes = std::fs::read(&file).unwrap();
    assert!(bytes.len() > 2 * MAGIC.len(), "{} bytes", bytes.len());
    assert_eq!(&bytes[..MAGIC.len()], MAGIC, "no MCAP header");
    assert_eq!(&bytes[bytes.len() - MAGIC.len()..], MAGIC, "not closed");
    let channel = b"/spacepose/pose";
    assert!(
        bytes.windows(channel.len()).any(|w| w == channel),
        "no pose channel in the file"
    );
}

/// Waits (20 s at most) for the recorder's heartbeat in `state`.
fn wait_health(health: &spacepose_bus::Subscriber<Health>, state: ServiceState) {
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        while let Some(h) = health.try_recv().unwrap() {
            if h.instance.as_str() == "recorder" && h.state == state as u8 {
                return;
            }
        }
        assert!(Instant::now() < deadline, "no {state:?} heartbeat");
        std::thread::sleep(Duration::from_millis(10));
    }
}
