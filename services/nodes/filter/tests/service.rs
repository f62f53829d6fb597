//! Process-level test: the real `spacepose-filter` binary on a private prefix.
#![allow(clippy::unwrap_used)] // tests may unwrap

use spacepose_bus::Bus;
use spacepose_geometry::{Pose, so3};
use spacepose_messages::{
    AcquisitionResult, FilterState, Health, Names, PoseEstimate, ServiceState, WireStatus,
};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Kills the service if the test fails before stopping it.
struct Service(Child);

impl Drop for Service {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

impl Service {
    fn start(prefix: &str) -> Service {
        let child = Command::new(env!("CARGO_BIN_EXE_spacepose-filter"))
            .args([
                "--prefix",
                prefix,
                "--instance",
                "filter-t",
                "--heartbeat-ms",
                "50",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap();
        Service(child)
    }

    /// SIGTERM, then the exit status within 5 s.
    fn terminate(&mut self) -> std::process::ExitStatus {
        let pid = self.0.id().to_string();
        assert!(
            Command::new("kill")
                .args(["-TERM", &pid])
                .status()
                .unwrap()
                .success()
        );
        let deadline = Instant::now() + Duration::from_secs(5);
        loop {
            if let Some(status) = self.0.try_wait().unwrap() {
                return status;
            }
            assert!(Instant::now() < deadline, "no exit after SIGTERM");
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

fn prefix() -> String {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .subsec_nanos();
    format!("tfilter{}x{}", std::process::id(), nanos % 1_000_000)
}

/// Polls `recv` until `accept` takes a message or 10 s pass.
fn wait_for<T>(mut recv: impl FnMut() -> Option<T>, mut accept: impl FnMut(&T) -> bool) -> T {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        while let Some(m) = recv() {
            if accept(&m) {
                return m;
            }
        }
        assert!(Instant::now() < deadline, "timed out");
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn pose_at(t: f64) -> Pose {
    Pose::new(
        so3::exp(&nalgebra::Vector3::new(0.0, 0.05 * t, 0.0)),
        nalgebra::Vector3::new(0.1, 0.0, 15.0),
    )
}

#[test]
fn the_filter_publishes_its_state_after_a_pose() {
    let prefix = prefix();
    let names = Names::new(&prefix).unwrap();
    let bus = Bus::open(&names, "test").unwrap();
    let health = bus.subscriber::<Health>(&names.health()).unwrap();
    let states = bus
        .subscriber::<FilterState>(&names.filter_state())
        .unwrap();
    let poses = bus.publisher::<PoseEstimate>(&names.pose()).unwrap();
    let acquisitions = bus
        .publisher::<AcquisitionResult>(&names.acquisition())
        .unwrap();
    let mut service = Service::start(&prefix);

    // Up (its subscribers exist once it sends heartbeats), not initialised.
    wait_for(
        || health.try_recv().unwrap(),
        |h| h.instance.as_str() == "filter-t",
    );
    let s = wait_for(|| states.try_recv().unwrap(), |_| true);
    assert_eq!(s.initialized, 0, "heartbeat state before any acquisition");

    let mut a = AcquisitionResult::new();
    a.success = 1;
    a.sequence = 0;
    a.t_s = 10.0;
    a.set_pose(&pose_at(10.0));
    acquisitions.send(&a).unwrap();
    let s = wait_for(|| states.try_recv().unwrap(), |s| s.initialized == 1);
    assert_eq!(s.t_s, 10.0);

    let mut e = PoseEstimate::new();
    e.sequence = 1;
    e.t_s = 11.0;
    e.status = WireStatus::Tracking as u8;
    e.set_pose(&pose_at(11.0));
    poses.send(&e).unwrap();
    let s = wait_for(|| states.try_recv().unwrap(), |s| s.t_s == 11.0);
    assert_eq!(s.initialized, 1);
    assert!(s.sequence >= 2, "init + one update, got {}", s.sequence);
    let (angle, dist) = s.pose().unwrap().error_to(&pose_at(11.0));
    // Between the initial pose and the measurement (0.05 rad apart).
    assert!(angle < 0.05 && dist < 0.01, "{angle} {dist}");
    assert!(s.published_ns > 0);

    // A degraded estimate is reported, not fused: the heartbeat still says 11 s.
    e.sequence = 2;
    e.t_s = 12.0;
    e.status = WireStatus::Degraded as u8;
    poses.send(&e).unwrap();
    let h = wait_for(|| health.try_recv().unwrap(), |h| h.counters.frames_in >= 2);
    assert_eq!(h.state, ServiceState::Running as u8);
    let s = wait_for(|| states.try_recv().unwrap(), |_| true);
    assert_eq!(s.t_s, 11.0);

    assert!(service.terminate().success());
    let last = wait_for(
        || health.try_recv().unwrap(),
        |h| h.state == ServiceState::Stopping as u8,
    );
    assert_eq!(last.instance.as_str(), "filter-t");
}
