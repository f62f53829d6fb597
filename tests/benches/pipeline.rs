//! Pipeline overhead per frame over the real service processes:
//! (pose published − raw cloud published by the sensor) − tracker compute,
//! i.e. what ingest, two iceoryx2 hops and the wake-ups add to the
//! registration. Target: median ≤ 1 ms.
//!
//! Each Criterion iteration waits for the next frame and reports its
//! overhead (`iter_custom`), so Criterion's statistics are over frames.
//! The median over every frame seen is also printed and written to
//! `target/release/e2e/pipeline.json`.

use criterion::{Criterion, SamplingMode, criterion_group, criterion_main};
use spacepose_bus::{Bus, CloudSubscriber, Subscriber};
use spacepose_e2e::*;
use spacepose_messages::{Names, PoseEstimate};
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

const FRAMES: u64 = 90;
const RATE_HZ: f64 = 10.0;

struct Follow {
    poses: Subscriber<PoseEstimate>,
    raw: CloudSubscriber,
    raw_ns: BTreeMap<u64, i64>,
    overhead_ms: Vec<f64>,
    tracker_hop_ms: Vec<f64>,
}

impl Follow {
    /// Overhead of the next frame with a known sensor publish time.
    fn next(&mut self) -> Duration {
        let deadline = Instant::now() + Duration::from_secs(30);
        loop {
            while let Some(c) = self.raw.try_recv().expect("raw cloud") {
                self.raw_ns
                    .insert(c.header().sequence, c.header().published_ns);
            }
            if let Some(p) = self.poses.try_recv().expect("pose") {
                if let Some(raw) = self.raw_ns.get(&p.sequence) {
                    let overhead = (p.published_ns - raw) as f64 * 1e-6 - p.total_ms;
                    let hop = (p.published_ns - p.cloud_published_ns) as f64 * 1e-6 - p.total_ms;
                    self.overhead_ms.push(overhead);
                    self.tracker_hop_ms.push(hop);
                    return Duration::from_secs_f64(overhead.max(0.0) * 1e-3);
                }
                continue;
            }
            assert!(
                Instant::now() < deadline,
                "no pose for 30 s: the suite stopped early"
            );
            std::thread::sleep(Duration::from_micros(200));
        }
    }
}

fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn pipeline(c: &mut Criterion) {
    require_suite();
    let dir = scratch_dir("pipeline-bench");
    let prefix = unique_prefix("bench");
    let _down = DownOnDrop(prefix.clone());
    let deploy = demo_descriptor(&dir, FRAMES, RATE_HZ);
    let names = Names::new(&prefix).expect("prefix");
    let bus = Bus::open(&names, "e2e-pipeline-bench").expect("bus");
    let mut f = Follow {
        poses: bus.subscriber(&names.pose()).expect("pose subscriber"),
        raw: bus
            .cloud_subscriber(&names.raw_cloud())
            .expect("raw subscriber"),
        raw_ns: BTreeMap::new(),
        overhead_ms: Vec::new(),
        tracker_hop_ms: Vec::new(),
    };
    let port = free_port().to_string();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let up = spacepose(&[
        "up",
        deploy.to_str().expect("utf-8 path"),
        "--prefix",
        &prefix,
        "--listen",
        &endpoint,
    ]);
    assert!(up.status.success(), "{}", text(&up));
    // Skip the first frames (map loading, acquisition, filter start).
    for _ in 0..5 {
        f.next();
    }
    f.overhead_ms.clear();
    f.tracker_hop_ms.clear();

    let mut g = c.benchmark_group("pipeline");
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(60)
        .warm_up_time(Duration::from_millis(1))
        .measurement_time(Duration::from_millis(1));
    g.bench_function("overhead_per_frame", |b| {
        b.iter_custom(|iters| (0..iters).map(|_| f.next()).sum())
    });
    g.finish();

    let m = median(&f.overhead_ms);
    let hop = median(&f.tracker_hop_ms);
    let max = f
        .overhead_ms
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    println!(
        "pipeline overhead over {} frames at {RATE_HZ} Hz: median {m:.3} ms, max {max:.3} ms \
         (ingest->pose hop minus tracker: median {hop:.3} ms); target <= 1 ms",
        f.overhead_ms.len()
    );
    let json = serde_json::json!({
        "frames": f.overhead_ms.len(),
        "rate_hz": RATE_HZ,
        "overhead_ms_median": m,
        "overhead_ms_max": max,
        "tracker_hop_overhead_ms_median": hop,
        "overhead_ms": f.overhead_ms,
    });
    let out = bin_dir().join("e2e").join("pipeline.json");
    std::fs::write(&out, serde_json::to_string_pretty(&json).expect("json")).expect("write");
    let down = spacepose(&["down", "--prefix", &prefix]);
    assert!(down.status.success(), "{}", text(&down));
}

criterion_group!(benches, pipeline);
criterion_main!(benches);
