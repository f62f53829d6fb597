//! The `spacepose-ingest` binary as a real process, fed and read through the bus.
#![allow(clippy::unwrap_used)] // tests may unwrap (clippy.toml only covers #[test] fns)

use spacepose_bus::{Bus, CloudSubscriber, Subscriber};
use spacepose_geometry::Point;
use spacepose_messages::{CloudHeader, FilterState, Health, Names, ServiceState};
use spacepose_runtime::testing::{self, ChildGuard};
use std::process::Command;
use std::time::Duration;

/// Polls until `f` gives a value (20 s at most).
fn wait_for<T>(what: &str, f: impl FnMut() -> Option<T>) -> T {
    testing::wait_for(what, Duration::from_secs(20), f)
}

/// The latest health message once `pred` holds for it.
fn health_until(sub: &Subscriber<Health>, what: &str, pred: impl Fn(&Health) -> bool) -> Health {
    wait_for(what, || {
        let mut found = None;
        while let Some(h) = sub.try_recv().unwrap() {
            if pred(&h) {
                found = Some(h);
            }
        }
        found
    })
}

fn next_cloud(sub: &CloudSubscriber) -> (CloudHeader, Vec<Point>) {
    wait_for("a cropped cloud", || {
        sub.try_recv()
            .unwrap()
            .map(|s| (*s.header(), s.points().to_vec()))
    })
}

/// A 1 m cube of points about (0, 0, 10) plus a wall at 16 m.
fn scene(n: usize, t0: f64) -> Vec<Point> {
    (0..n)
        .map(|i| {
            let f = i as f32 / n as f32;
            let t = t0 + 0.5 * i as f64 / n as f64;
            if i % 4 == 0 {
                Point::new(4.0 * f - 2.0, 1.0 - 2.0 * f, 16.0, 1.0, t)
            } else {
                Point::new(
                    f - 0.5,
                    (f * 7.0).fract() - 0.5,
                    9.5 + (f * 13.0).fract(),
                    1.0,
                    t,
                )
            }
        })
        .collect()
}

#[test]
fn ingest_crops_counts_bad_frames_and_keeps_going() {
    let prefix = testing::unique_prefix("ingest");
    let names = Names::new(&prefix).unwrap();
    let bus = Bus::open(&names, "ingest-test").unwrap();
    let health = bus.subscriber::<Health>(&names.health()).unwrap();
    let cloud = bus.cloud_subscriber(&names.cloud()).unwrap();
    let raw = bus.cloud_publisher(&names.raw_cloud(), 60_000).unwrap();
    let filter = bus.publisher::<FilterState>(&names.filter_state()).unwrap();

    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("ingest.toml");
    std::fs::write(&config, "max_points = 50000\n").unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_spacepose-ingest"))
        .args(["--prefix", &prefix, "--heartbeat-ms", "20", "--config"])
        .arg(&config)
        .spawn()
        .unwrap();
    let mut guard = ChildGuard(child);
    health_until(&health, "the first heartbeat", |h| {
        h.state == ServiceState::Running as u8 && h.service.as_str() == "ingest"
    });

    // 1. A frame with NaN points: cropped, NaNs dropped and counted.
    let mut pts = scene(4000, 1.0);
    for p in pts.iter_mut().step_by(10) {
        p.x = f32::NAN;
    }
    raw.send(CloudHeader::new(1, 1.0, 1.5), &pts).unwrap();
    let (h1, out1) = next_cloud(&cloud);
    assert_eq!(h1.sequence, 1);
    assert_eq!((h1.scan_start_s, h1.scan_end_s), (1.0, 1.5));
    assert_eq!(h1.point_count as usize, out1.len());
    // Without a prediction ingest finds the target in the frame (the
    // densest sphere of its bounding radius): every finite point of the
    // cube goes on, and the 800 finite points of the wall 6 m behind do
    // not (ingest crops; the tracker voxel-filters after its motion
    // compensation).
    assert_eq!(out1.len(), 2800);
    assert!(out1.iter().all(|p| p.is_finite() && p.z < 12.0));

    // 2. An empty frame with a valid header (the sensor saw nothing): an
    //    observation, forwarded empty with its own header, not rejected.
    raw.send(CloudHeader::new(2, 2.0, 2.5), &[]).unwrap();
    let (h2, out2) = next_cloud(&cloud);
    assert_eq!((h2.sequence, h2.scan_start_s, h2.scan_end_s), (2, 2.0, 2.5));
    assert_eq!((h2.point_count, out2.len()), (0, 0));
    // 3. An oversized frame: counted, nothing published.
    raw.send(CloudHeader::new(3, 3.0, 3.5), &scene(55_000, 3.0))
        .unwrap();
    health_until(&health, "the oversized frame", |h| {
        h.counters.rejected_oversized == 1
    });

    // 4. With a filter state, the wall at 16 m is cropped out.
    let mut state = FilterState::new();
    state.initialized = 1;
    state.t_s = 4.0;
    state.p_sensor_target = [0.0, 0.0, 10.0];
    filter.send(&state).unwrap();
    let good = scene(4000, 4.0);
    raw.send(CloudHeader::new(4, 4.0, 4.5), &good).unwrap();
    let (h4, out4) = next_cloud(&cloud);
    assert_eq!(h4.sequence, 4);
    assert!(!out4.is_empty());
    assert!(out4.iter().all(|p| p.z < 12.0), "the wall must be cropped");
    assert_eq!(out4.len(), 3000, "every point of the cube");
    assert!(
        cloud.try_recv().unwrap().is_none(),
        "rejected frames publish nothing"
    );

    let h = health_until(&health, "the final counters", |h| {
        h.counters.frames_out == 3
    });
    assert_eq!(h.counters.frames_in, 4);
    assert_eq!(h.counters.rejected_non_finite, 1);
    assert_eq!(
        (h.counters.rejected_empty, h.counters.rejected_oversized),
        (0, 1)
    );
    assert_eq!(h.counters.last_frame, 4);

    // SIGTERM: a clean exit with a Stopping heartbeat.
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
    health_until(&health, "the stopping heartbeat", |h| {
        h.state == ServiceState::Stopping as u8
    });
}
