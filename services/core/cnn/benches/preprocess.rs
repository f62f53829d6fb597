//! Preprocessing time (trimmed centroid + ROI + depth image, seed 004
//! §III.A) of one simulated 10k-point `deos` frame at 10 m, for N = 64, 96,
//! 128 and 224 (the trade-off is written in `src/preprocess.rs`).
//!
//! `cargo bench -p spacepose-cnn --bench preprocess -- --warm-up-time 1 --measurement-time 3`

#![allow(missing_docs)]

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::{Rotation3, Vector3};
use spacepose_cnn::{PreprocessConfig, preprocess};
use spacepose_geometry::Pose;
use spacepose_lidar_sim::{LidarSimulator, SensorConfig};
use spacepose_model::Target;
use spacepose_scenario::TruthState;
use std::hint::black_box;
use std::sync::Arc;

fn bench_preprocess(c: &mut Criterion) {
    let deos = Arc::new(Target::builtin("deos").expect("built-in deos"));
    let sim = LidarSimulator::new(deos.clone(), SensorConfig::livox_mid40()).expect("simulator");
    let truth = TruthState {
        t: 1.0,
        t_sensor_target: Pose::new(
            Rotation3::from_euler_angles(0.3, 0.5, 0.8),
            Vector3::new(0.0, 0.0, 10.0),
        ),
        v_sensor_target: Vector3::zeros(),
        w_target: Vector3::zeros(),
    };
    let frame = sim.simulate(&truth, &mut LidarSimulator::frame_rng(1, 0));
    let mut group = c.benchmark_group(format!("preprocess_{}_points", frame.points.len()));
    for n in [64usize, 96, 128, 224] {
        let config = PreprocessConfig::for_target(&deos, n).expect("config");
        group.bench_with_input(BenchmarkId::from_parameter(n), &config, |b, config| {
            b.iter(|| preprocess(black_box(&frame.points), config).expect("image"))
        });
    }
    group.finish();
}

criterion_group!(benches, bench_preprocess);
criterion_main!(benches);
