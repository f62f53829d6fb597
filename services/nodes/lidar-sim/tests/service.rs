//! The `spacepose-lidar-sim` binary as a real process, read through the bus.
#![allow(clippy::unwrap_used)] // tests may unwrap (clippy.toml only covers #[test] fns)

use spacepose_bus::Bus;
use spacepose_messages::convert::pose_from_wire;
use spacepose_messages::{AcquisitionResult, Health, Names, ServiceState, TruthMsg};
use spacepose_runtime::testing::{self, ChildGuard};
use std::process::Command;
use std::time::Duration;

/// Polls until `f` gives a value (60 s at most).
fn wait_for<T>(what: &str, f: impl FnMut() -> Option<T>) -> T {
    testing::wait_for(what, Duration::from_secs(60), f)
}

#[test]
fn lidar_sim_publishes_frames_truth_and_the_truth_acquisition() {
    let prefix = testing::unique_prefix("sim");
    let names = Names::new(&prefix).unwrap();
    let bus = Bus::open(&names, "sim-test").unwrap();
    let health = bus.subscriber::<Health>(&names.health()).unwrap();
    let raw = bus.cloud_subscriber(&names.raw_cloud()).unwrap();
    let truth = bus.subscriber::<TruthMsg>(&names.truth()).unwrap();
    let acquisition = bus
        .subscriber::<AcquisitionResult>(&names.acquisition())
        .unwrap();

    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("lidar-sim.toml");
    let text = "scenario = \"tumbling\"\nseed = 3\nframes = 3\nrate_hz = 0.0\n\
                integration_time_s = 0.2\ntruth_init = true\n";
    std::fs::write(&config, text).unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_spacepose-lidar-sim"))
        .args(["--prefix", &prefix, "--heartbeat-ms", "20", "--config"])
        .arg(&config)
        .spawn()
        .unwrap();
    let mut guard = ChildGuard(child);

    let mut frames = Vec::new();
    while frames.len() < 3 {
        let f = wait_for("a raw frame", || {
            raw.try_recv()
                .unwrap()
                .map(|s| (*s.header(), s.points().to_vec()))
        });
        frames.push(f);
    }
    for (k, (h, pts)) in frames.iter().enumerate() {
        assert_eq!(h.sequence, k as u64);
        assert_eq!(h.point_count as usize, pts.len());
        assert!(pts.len() > 1000, "{} points", pts.len());
        assert!((h.scan_end_s - h.scan_start_s - 0.2).abs() < 1e-6);
        let t_ok = pts
            .iter()
            .all(|p| p.t >= h.scan_start_s - 1e-9 && p.t <= h.scan_end_s + 1e-9);
        assert!(t_ok);
        // Clutter on: returns far behind the target (the back wall).
        let far = pts.iter().filter(|p| p.z > 20.0).count();
        assert!(far > 100, "{far} far returns");
    }
    let truths: Vec<TruthMsg> = (0..3)
        .map(|_| wait_for("a truth message", || truth.try_recv().unwrap()))
        .collect();
    for (k, t) in truths.iter().enumerate() {
        assert_eq!(t.sequence, k as u64);
        assert_eq!(t.t_s, frames[k].0.scan_end_s);
        pose_from_wire(&t.q_sensor_target, &t.p_sensor_target).unwrap();
    }
    let acq = wait_for("the truth acquisition", || acquisition.try_recv().unwrap());
    assert_eq!((acq.method, acq.success, acq.sequence), (0, 1, 0));
    assert_eq!(acq.t_s, truths[0].t_s);
    assert_eq!(acq.p_sensor_target, truths[0].p_sensor_target);
    assert!(
        acquisition.try_recv().unwrap().is_none(),
        "only the first frame"
    );

    let h = wait_for("health", || {
        let mut last = None;
        while let Some(h) = health.try_recv().unwrap() {
            last = Some(h);
        }
        last.filter(|h| h.counters.frames_out == 3)
    });
    assert_eq!((h.counters.errors, h.counters.last_frame), (0, 2));

    let pid = guard.0.id().to_string();
    assert!(
        Command::new("kill")
            .args(["-TERM", &pid])
            .status()
            .unwrap()
            .success()
    );
    let status = wait_for("the exit", || guard.0.try_wait().unwrap());
    assert!(status.success(), "{status:?}");
    wait_for("the stopping heartbeat", || {
        let mut stop = None;
        while let Some(h) = health.try_recv().unwrap() {
            if h.state == ServiceState::Stopping as u8 {
                stop = Some(h);
            }
        }
        stop
    });
}

#[test]
fn lidar_sim_exits_after_its_last_frame_with_exit_at_end() {
    let prefix = testing::unique_prefix("simend");
    let names = Names::new(&prefix).unwrap();
    let bus = Bus::open(&names, "sim-test").unwrap();
    let health = bus.subscriber::<Health>(&names.health()).unwrap();
    let raw = bus.cloud_subscriber(&names.raw_cloud()).unwrap();

    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("lidar-sim.toml");
    let text = "seed = 4\nframes = 2\nrate_hz = 20.0\nintegration_time_s = 0.05\n\
                clutter = false\nexit_at_end = true\n";
    std::fs::write(&config, text).unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_spacepose-lidar-sim"))
        .args(["--prefix", &prefix, "--heartbeat-ms", "20", "--config"])
        .arg(&config)
        .spawn()
        .unwrap();
    let mut guard = ChildGuard(child);
    // The frames are read as they come (a sample lives as long as its
    // publisher), until the process ends on its own.
    let (mut sequences, mut last) = (Vec::new(), None);
    let status = wait_for("the exit", || {
        while let Some(s) = raw.try_recv().unwrap() {
            sequences.push(s.header().sequence);
        }
        while let Some(h) = health.try_recv().unwrap() {
            last = Some(h);
        }
        guard.0.try_wait().unwrap()
    });
    assert!(status.success(), "{status:?}");
    assert_eq!(sequences, [0, 1]);
    let last = last.unwrap();
    assert_eq!(last.state, ServiceState::Stopping as u8);
    assert_eq!((last.counters.frames_out, last.counters.last_frame), (2, 1));
}
