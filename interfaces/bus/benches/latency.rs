//! One-way latency over iceoryx2, event-driven: the publisher stamps
//! `published_ns` just before sending, the subscriber thread wakes on its
//! WaitSet, takes the sample and measures `realtime_ns() - published_ns`.
//! Back-to-back (the publisher waits for each measurement before the next
//! frame). Criterion reports the measured one-way times; the exact median
//! and p90 over every frame are printed at the end.

use criterion::{Criterion, criterion_group, criterion_main};
use spacepose_bus::{Bus, WakeReason};
use spacepose_geometry::Point;
use spacepose_messages::{CloudHeader, Names, PoseEstimate, realtime_ns};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

const POINTS: usize = 100_000;

fn names(tag: &str) -> Names {
    Names::new(&format!("bench-{}-{tag}", std::process::id())).expect("valid prefix")
}

/// Subscriber thread: wakes on the WaitSet, sends back one-way latencies (ns).
fn spawn_receiver(
    names: Names,
    cloud: bool,
    stop: Arc<AtomicBool>,
) -> (mpsc::Receiver<i64>, std::thread::JoinHandle<()>) {
    let (tx, rx) = mpsc::channel();
    let (ready_tx, ready_rx) = mpsc::channel();
    let handle = std::thread::spawn(move || {
        let bus = Bus::open(&names, "bench-sub").expect("bus");
        let clouds = bus
            .cloud_subscriber(&names.cloud())
            .expect("cloud subscriber");
        let poses = bus
            .subscriber::<PoseEstimate>(&names.pose())
            .expect("pose subscriber");
        let mut waiter = bus.waitset_without_signals().expect("waiter");
        if cloud {
            waiter.attach(&clouds).expect("attach");
        } else {
            waiter.attach(&poses).expect("attach");
        }
        ready_tx.send(()).expect("ready");
        while !stop.load(Ordering::Relaxed) {
            if waiter.wait(Duration::from_millis(100)).expect("wait") != WakeReason::Notified {
                continue;
            }
            while let Some(s) = clouds.try_recv().expect("receive") {
                let now = realtime_ns();
                let _ = tx.send(now - s.header().published_ns);
            }
            while let Some(p) = poses.try_recv().expect("receive") {
                let now = realtime_ns();
                let _ = tx.send(now - p.published_ns);
            }
        }
    });
    ready_rx.recv().expect("receiver ready");
    (rx, handle)
}

fn percentile(samples: &mut [i64], p: f64) -> f64 {
    samples.sort_unstable();
    let i = ((samples.len() as f64 - 1.0) * p).round() as usize;
    samples.get(i).copied().unwrap_or(0) as f64 * 1e-3
}

fn report(label: &str, samples: &mut [i64]) {
    let p50 = percentile(samples, 0.5);
    let p90 = percentile(samples, 0.9);
    println!(
        "{label}: {} frames, one-way median {p50:.1} us, p90 {p90:.1} us",
        samples.len()
    );
}

fn cloud_latency(c: &mut Criterion) {
    let names = names("cloud");
    let stop = Arc::new(AtomicBool::new(false));
    let (latencies, receiver) = spawn_receiver(names.clone(), true, stop.clone());
    let bus = Bus::open(&names, "bench-pub").expect("bus");
    let publisher = bus
        .cloud_publisher(&names.cloud(), POINTS)
        .expect("cloud publisher");
    let points: Vec<Point> = (0..POINTS)
        .map(|i| Point::new(i as f32, 1.0, 2.0, 0.5, 1e-6 * i as f64))
        .collect();
    let mut all = Vec::new();
    let mut sequence = 0;
    c.bench_function("iceoryx2_cloud_100k_one_way", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                sequence += 1;
                publisher
                    .send(CloudHeader::new(sequence, 0.0, 0.1), &points)
                    .expect("send");
                let ns = latencies.recv().expect("latency");
                all.push(ns);
                total += Duration::from_nanos(ns.max(0) as u64);
            }
            total
        })
    });
    stop.store(true, Ordering::Relaxed);
    receiver.join().expect("receiver");
    report("iceoryx2 100k-point cloud", &mut all);
}

fn pose_latency(c: &mut Criterion) {
    let names = names("pose");
    let stop = Arc::new(AtomicBool::new(false));
    let (latencies, receiver) = spawn_receiver(names.clone(), false, stop.clone());
    let bus = Bus::open(&names, "bench-pub").expect("bus");
    let publisher = bus
        .publisher::<PoseEstimate>(&names.pose())
        .expect("pose publisher");
    let mut all = Vec::new();
    c.bench_function("iceoryx2_pose_one_way", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for i in 0..iters {
                let mut m = PoseEstimate::new();
                m.sequence = i;
                publisher.send(&m).expect("send");
                let ns = latencies.recv().expect("latency");
                all.push(ns);
                total += Duration::from_nanos(ns.max(0) as u64);
            }
            total
        })
    });
    stop.store(true, Ordering::Relaxed);
    receiver.join().expect("receiver");
    report("iceoryx2 PoseEstimate", &mut all);
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(50)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    targets = cloud_latency, pose_latency
}
criterion_main!(benches);
