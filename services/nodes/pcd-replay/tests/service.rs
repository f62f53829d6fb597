//! The `spacepose-pcd-replay` binary as a real process, read through the bus.
#![allow(clippy::unwrap_used)] // tests may unwrap (clippy.toml only covers #[test] fns)

use spacepose_bus::Bus;
use spacepose_geometry::{CloudFormat, Point, write_cloud};
use spacepose_messages::{Health, Names, ServiceState};
use spacepose_runtime::testing::{self, ChildGuard};
use std::process::Command;
use std::time::Duration;

/// Polls until `f` gives a value (20 s at most).
fn wait_for<T>(what: &str, f: impl FnMut() -> Option<T>) -> T {
    testing::wait_for(what, Duration::from_secs(20), f)
}

fn frame(k: usize) -> Vec<Point> {
    (0..500 + k)
        .map(|i| {
            Point::new(
                i as f32 * 0.001,
                0.0,
                10.0,
                1.0,
                k as f64 + 0.3 + i as f64 * 1e-3,
            )
        })
        .collect()
}

#[test]
fn replay_publishes_frames_in_order_skips_corrupt_files_and_loops() {
    let prefix = testing::unique_prefix("replay");
    let names = Names::new(&prefix).unwrap();
    let bus = Bus::open(&names, "replay-test").unwrap();
    let health = bus.subscriber::<Health>(&names.health()).unwrap();
    let raw = bus.cloud_subscriber(&names.raw_cloud()).unwrap();

    let dir = tempfile::tempdir().unwrap();
    for k in [0, 2] {
        let path = dir.path().join(format!("frame_{k:06}.pcd"));
        write_cloud(&path, &frame(k), CloudFormat::PcdBinary).unwrap();
    }
    std::fs::write(dir.path().join("frame_000001.pcd"), "corrupt").unwrap();
    let truth = "frame,scan_start_s,scan_end_s\n0,0.28,1.0\n1,1.28,2.0\n2,2.28,3.0\n";
    std::fs::write(dir.path().join("truth.csv"), truth).unwrap();
    let config = dir.path().join("replay.toml");
    let text = format!(
        "dir = {:?}\nrate_hz = 25.0\nloop = true\n",
        dir.path().display().to_string()
    );
    std::fs::write(&config, text).unwrap();

    let child = Command::new(env!("CARGO_BIN_EXE_spacepose-pcd-replay"))
        .args(["--prefix", &prefix, "--heartbeat-ms", "20", "--config"])
        .arg(&config)
        .spawn()
        .unwrap();
    let mut guard = ChildGuard(child);

    let mut got = Vec::new();
    while got.len() < 5 {
        let (h, pts) = wait_for("a raw cloud", || {
            raw.try_recv()
                .unwrap()
                .map(|s| (*s.header(), s.points().to_vec()))
        });
        got.push((h, pts));
    }
    // Pass 1: frames 0 and 2 (1 is corrupt), then pass 2 continues the clock.
    for (i, (h, pts)) in got.iter().enumerate() {
        assert_eq!(h.sequence, i as u64);
        let k = [0, 2][i % 2];
        assert_eq!(pts.len(), 500 + k);
        assert_eq!(h.point_count as usize, pts.len());
    }
    assert_eq!((got[0].0.scan_start_s, got[0].0.scan_end_s), (0.28, 1.0));
    assert_eq!((got[1].0.scan_start_s, got[1].0.scan_end_s), (2.28, 3.0));
    // Loop shift = (3.0 - 0.28) + 0.04 s.
    let shift = 2.72 + 0.04;
    assert!((got[2].0.scan_end_s - (1.0 + shift)).abs() < 1e-9);
    assert!((got[2].1[0].t - (got[0].1[0].t + shift)).abs() < 1e-9);
    assert_eq!(got[2].1[0].x, got[0].1[0].x);

    let h = wait_for("health with errors", || {
        let mut last = None;
        while let Some(h) = health.try_recv().unwrap() {
            last = Some(h);
        }
        last.filter(|h| h.counters.errors >= 2 && h.counters.frames_out >= 5)
    });
    assert_eq!(h.service.as_str(), "pcd-replay");

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
fn replay_exits_after_the_last_frame_with_exit_at_end() {
    let prefix = testing::unique_prefix("replend");
    let names = Names::new(&prefix).unwrap();
    let bus = Bus::open(&names, "replay-test").unwrap();
    let health = bus.subscriber::<Health>(&names.health()).unwrap();
    let raw = bus.cloud_subscriber(&names.raw_cloud()).unwrap();

    let dir = tempfile::tempdir().unwrap();
    for k in [0, 1] {
        let path = dir.path().join(format!("frame_{k:06}.ply"));
        write_cloud(&path, &frame(k), CloudFormat::PlyBinary).unwrap();
    }
    let config = dir.path().join("replay.toml");
    let text = format!(
        "dir = {:?}\nrate_hz = 20.0\nexit_at_end = true\nsensor_id = 9\n",
        dir.path().display().to_string()
    );
    std::fs::write(&config, text).unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_spacepose-pcd-replay"))
        .args(["--prefix", &prefix, "--heartbeat-ms", "20", "--config"])
        .arg(&config)
        .spawn()
        .unwrap();
    let mut guard = ChildGuard(child);
    // Read as they come: a sample lives as long as its publisher.
    let (mut headers, mut last) = (Vec::new(), None);
    let status = wait_for("the exit", || {
        while let Some(s) = raw.try_recv().unwrap() {
            headers.push(*s.header());
        }
        while let Some(h) = health.try_recv().unwrap() {
            last = Some(h);
        }
        guard.0.try_wait().unwrap()
    });
    assert!(status.success(), "{status:?}");
    let seen: Vec<_> = headers.iter().map(|h| (h.sequence, h.sensor_id)).collect();
    assert_eq!(seen, [(0, 9), (1, 9)]);
    // No truth.csv: the scan times are the points' (frame k from k + 0.3 s).
    assert_eq!(headers[1].scan_start_s, 1.3);
    let last = last.unwrap();
    assert_eq!(last.state, ServiceState::Stopping as u8);
    assert_eq!((last.counters.frames_out, last.counters.errors), (2, 0));
}
