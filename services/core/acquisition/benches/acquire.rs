//! `acquire`: one template-matching acquisition (Δ = 30°, one thread) of
//! envisat at 30 m seen by the seed 002 raster sensor with every effect.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use spacepose_acquisition::{TemplateMatcher, TemplateMatchingConfig, Threads};
use spacepose_geometry::{Euler321, Pose};
use spacepose_lidar_sim::{LidarSimulator, SensorConfig};
use spacepose_model::Target;
use spacepose_scenario::TruthState;
use std::hint::black_box;
use std::sync::Arc;

fn bench_acquire(c: &mut Criterion) {
    let target = Arc::new(Target::builtin("envisat").expect("envisat"));
    let sensor = SensorConfig::raster_seed002();
    let sim = LidarSimulator::new(target.clone(), sensor.clone()).expect("simulator");
    let truth = TruthState {
        t: 1.0,
        t_sensor_target: Pose::new(
            Euler321::from_degrees(40.0, 15.0, -110.0).to_rotation(),
            Vector3::new(0.2, -0.3, 30.0),
        ),
        v_sensor_target: Vector3::zeros(),
        w_target: Vector3::zeros(),
    };
    let frame = sim.simulate(&truth, &mut LidarSimulator::frame_rng(11, 0));
    let mut group = c.benchmark_group("acquire");
    group.sample_size(10);
    for (name, config) in [
        ("delta30_single", TemplateMatchingConfig::default()),
        (
            "delta30_single_fast",
            TemplateMatchingConfig {
                fast: true,
                ..Default::default()
            },
        ),
    ] {
        let config = TemplateMatchingConfig {
            threads: Threads::Single,
            ..config
        };
        let matcher =
            TemplateMatcher::new(target.clone(), sensor.clone(), config).expect("matcher");
        group.bench_function(name, |b| {
            b.iter(|| matcher.acquire(black_box(&frame.points)).expect("acquire"))
        });
    }
    group.finish();
}

criterion_group!(benches, bench_acquire);
criterion_main!(benches);
