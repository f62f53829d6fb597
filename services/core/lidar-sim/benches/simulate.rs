//! Frames per second of the simulator on one core: a `deos` frame at 10 m,
//! tumbling at 10°/s, with every effect on (without, then with clutter).
//!
//! `cargo bench -p spacepose-lidar-sim -- --warm-up-time 1 --measurement-time 5`

#![allow(missing_docs)]

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{Rotation3, Vector3};
use spacepose_geometry::Pose;
use spacepose_lidar_sim::{Effects, LidarSimulator, SensorConfig};
use spacepose_model::Target;
use spacepose_scenario::TruthState;
use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

fn truth() -> TruthState {
    TruthState {
        t: 100.0,
        t_sensor_target: Pose::new(
            Rotation3::from_euler_angles(0.3, 0.5, 0.8),
            Vector3::new(0.0, 0.0, 10.0),
        ),
        v_sensor_target: Vector3::new(0.02, -0.01, 0.02),
        w_target: Vector3::new(0.3, 1.0, 0.5).normalize() * 10f64.to_radians(),
    }
}

/// CPU time of the calling thread (s), from `/proc/thread-self/schedstat` (Linux).
fn thread_cpu_seconds() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = text.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

fn bench_simulate(c: &mut Criterion) {
    let target = Arc::new(Target::builtin("deos").expect("built-in deos target"));
    let truth = truth();
    let mut group = c.benchmark_group("simulate");
    group.throughput(Throughput::Elements(1)); // elem/s = frames/s
    group.sample_size(10);
    for (name, effects) in [
        ("deos_10m_all_effects", Effects::default()),
        ("deos_10m_all_effects_clutter", Effects::all()),
    ] {
        let config = SensorConfig {
            effects,
            ..SensorConfig::livox_mid40()
        };
        let sim = LidarSimulator::new(target.clone(), config).expect("valid configuration");
        // A plain timing first, printed as frames/s: wall clock, and CPU time
        // of this thread (the machine is shared, so wall time overstates cost).
        let frames = 40u64;
        let (start, cpu_start) = (Instant::now(), thread_cpu_seconds());
        let mut points = 0;
        for k in 0..frames {
            points += sim
                .simulate(&truth, &mut LidarSimulator::frame_rng(1, k))
                .points
                .len();
        }
        let fps = frames as f64 / start.elapsed().as_secs_f64();
        let cpu = match (cpu_start, thread_cpu_seconds()) {
            (Some(a), Some(b)) => format!(", {:.1} frames per CPU-second", frames as f64 / (b - a)),
            _ => String::new(),
        };
        println!(
            "{name}: {fps:.1} frames/s (wall, one thread){cpu}, {} points per frame",
            points / frames as usize
        );
        let mut k = 0u64;
        group.bench_function(name, |b| {
            b.iter(|| {
                k += 1;
                black_box(sim.simulate(&truth, &mut LidarSimulator::frame_rng(1, k)))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_simulate);
criterion_main!(benches);
