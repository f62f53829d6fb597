//! Process-level test: the real `spacepose-tracker` binary on a private
//! prefix, fed simulated `deos` frames through iceoryx2.
#![allow(clippy::unwrap_used)] // tests may unwrap

use spacepose_bus::Bus;
use spacepose_geometry::Point;
use spacepose_lidar_sim::{Frame, LidarSimulator, SensorConfig};
use spacepose_messages::{
    AcquisitionResult, CloudHeader, Health, Names, PoseEstimate, ServiceState, WireStatus,
};
use spacepose_model::Target;
use spacepose_scenario::{ScenarioConfig, ScenarioKind, build};
use std::process::{Child, Command, Stdio};
use std::sync::Arc;
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
    /// SIGTERM, then the exit status within 5 s.
    fn terminate(&mut self) -> std::process::ExitStatus {
        let pid = self.0.id().to_string();
        let kill = Command::new("kill").args(["-TERM", &pid]).status();
        assert!(kill.unwrap().success());
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
    format!("ttrk{}x{}", std::process::id(), nanos % 1_000_000)
}

/// Polls `recv` until `accept` takes a message or `secs` pass.
fn wait_for<T>(
    secs: u64,
    mut recv: impl FnMut() -> Option<T>,
    mut accept: impl FnMut(&T) -> bool,
) -> T {
    let deadline = Instant::now() + Duration::from_secs(secs);
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

fn frames(n: usize) -> Vec<Frame> {
    let target = Arc::new(Target::builtin("deos").unwrap());
    let mut config = ScenarioConfig::default_for(ScenarioKind::SlowSpin);
    config.seed = 31;
    let scenario = build(&config).unwrap();
    let mut sensor = SensorConfig::livox_mid40();
    sensor.integration_time_s = 1.0;
    let sim = LidarSimulator::new(target, sensor).unwrap();
    scenario
        .frame_end_times(n)
        .iter()
        .enumerate()
        .map(|(k, &t)| {
            sim.simulate(
                &scenario.state_at(t),
                &mut LidarSimulator::frame_rng(31, k as u64),
            )
        })
        .collect()
}

fn errors(e: &PoseEstimate, f: &Frame) -> (f64, f64) {
    let (ang, pos) = e.pose().unwrap().error_to(&f.truth.t_sensor_target);
    (ang.to_degrees(), pos)
}

#[test]
fn the_tracker_answers_every_frame_and_survives_nan_frames() {
    let frames = frames(4);
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("deos.ndt");
    let config = dir.path().join("tracker.toml");
    let toml = format!(
        "target = \"deos\"\nmap_file = {:?}\ninstance = \"tracker-t\"\n[tracker]\nmode = \"ndt\"\n",
        map.to_str().unwrap()
    );
    std::fs::write(&config, toml).unwrap();

    let prefix = prefix();
    let names = Names::new(&prefix).unwrap();
    let bus = Bus::open(&names, "test").unwrap();
    let health = bus.subscriber::<Health>(&names.health()).unwrap();
    let poses = bus.subscriber::<PoseEstimate>(&names.pose()).unwrap();
    let capacity = frames.iter().map(|f| f.points.len()).max().unwrap();
    let clouds = bus.cloud_publisher(&names.cloud(), capacity).unwrap();
    let acquisitions = bus
        .publisher::<AcquisitionResult>(&names.acquisition())
        .unwrap();
    let mut service = Service(
        Command::new(env!("CARGO_BIN_EXE_spacepose-tracker"))
            .args(["--prefix", &prefix, "--heartbeat-ms", "50", "--config"])
            .arg(&config)
            .stdout(Stdio::null())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap(),
    );
    let send = |seq: u64, f: &Frame, points: &[Point]| {
        clouds
            .send(CloudHeader::new(seq, f.scan_start, f.scan_end), points)
            .unwrap();
        wait_for(60, || poses.try_recv().unwrap(), |p| p.sequence == seq)
    };

    // Up once it sends heartbeats (the model is built and the map saved first).
    wait_for(
        120,
        || health.try_recv().unwrap(),
        |h| h.instance.as_str() == "tracker-t",
    );
    assert!(map.exists(), "the NDT map was saved on first start");

    // Not initialised: a lost pose, still one per frame.
    let p = send(0, &frames[0], &frames[0].points);
    assert_eq!(p.wire_status().unwrap(), WireStatus::Lost);
    assert_eq!(p.instance.as_str(), "tracker-t");

    // A truth acquisition from frame 0, then frame 1 is tracked.
    let mut a = AcquisitionResult::new();
    a.success = 1;
    a.t_s = frames[0].scan_end;
    a.set_pose(&frames[0].truth.t_sensor_target);
    acquisitions.send(&a).unwrap();
    let p = send(1, &frames[1], &frames[1].points);
    assert_eq!(p.wire_status().unwrap(), WireStatus::Tracking);
    let (ang, pos) = errors(&p, &frames[1]);
    assert!(ang < 3.0 && pos < 0.08, "{ang} deg {pos} m");
    assert_eq!(p.t_s, frames[1].scan_end);
    assert!(p.cloud_published_ns > 0 && p.published_ns >= p.cloud_published_ns);
    assert!(p.total_ms > 0.0 && p.iterations > 0 && p.points_used > 0);

    // A NaN-only frame: lost, counted, and the next good frame still tracks.
    let nan = vec![Point::new(f32::NAN, f32::NAN, f32::NAN, 1.0, frames[2].scan_end); 500];
    let p = send(2, &frames[2], &nan);
    assert_eq!(p.wire_status().unwrap(), WireStatus::Lost);
    let h = wait_for(
        10,
        || health.try_recv().unwrap(),
        |h| h.counters.rejected_non_finite >= 1,
    );
    assert_eq!(h.counters.frames_out, 3);
    let p = send(3, &frames[3], &frames[3].points);
    assert_eq!(p.wire_status().unwrap(), WireStatus::Tracking);
    let (ang, pos) = errors(&p, &frames[3]);
    assert!(ang < 3.0 && pos < 0.08, "{ang} deg {pos} m");

    assert!(service.terminate().success());
    wait_for(
        10,
        || health.try_recv().unwrap(),
        |h| h.state == ServiceState::Stopping as u8,
    );
}
