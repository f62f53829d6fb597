//! The configured chain with the real template matcher on simulated frames:
//! a clean `deos` frame is acquired, a sparse or all-outlier cloud is a
//! failure result, never a false success.

#![allow(clippy::unwrap_used)] // test helpers

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spacepose_geometry::Point;
use spacepose_init_node::InitServiceConfig;
use spacepose_lidar_sim::LidarSimulator;
use spacepose_messages::{AcquisitionMethod, Name};
use spacepose_model::Target;
use spacepose_scenario::{ScenarioConfig, ScenarioKind};
use std::sync::Arc;

fn config() -> InitServiceConfig {
    let mut config = InitServiceConfig::default();
    if let Ok(text) = std::env::var("INIT_TM") {
        // Experiments: INIT_TM='fast = true' etc. (TOML of the template_matching table).
        let mut table: toml::Table =
            toml::from_str(&toml::to_string(&config.template_matching).unwrap()).unwrap();
        table.extend(toml::from_str::<toml::Table>(&text).unwrap());
        config.template_matching = table.try_into().unwrap();
    }
    config
}

#[test]
#[ignore = "fails: the template matcher does not accept deos/Mid-40 frames yet (f_CONV 0.04-0.05 m² > f_MAX 0.02, attitudes 90-170° off, also on noise-free frames: INIT_CLEAN=1)"]
fn simulated_deos_frames_are_acquired() {
    let config = config();
    let t0 = std::time::Instant::now();
    let chain = config.build_chain().unwrap();
    println!("chain built in {:.0} ms", t0.elapsed().as_secs_f64() * 1e3);
    let scenario = spacepose_scenario::build(&ScenarioConfig {
        seed: 7,
        ..ScenarioConfig::default_for(ScenarioKind::Tumbling)
    })
    .unwrap();
    let mut sensor = config.sensor();
    if std::env::var("INIT_CLEAN").is_ok() {
        sensor.effects = spacepose_lidar_sim::Effects::none();
    }
    let sim = LidarSimulator::new(Arc::new(Target::builtin("deos").unwrap()), sensor).unwrap();
    let instance = Name::new("init").unwrap();
    let mut successes = 0;
    for k in [0u64, 5, 10] {
        let truth = scenario.state_at((k + 1) as f64);
        let frame = sim.simulate(&truth, &mut LidarSimulator::frame_rng(7, k));
        let a = chain.acquire(&frame.points);
        let msg = a.to_wire(k, frame.scan_end, instance);
        println!("frame {k}: {}", a.summary());
        if let Some(Ok(out)) = a.reported().map(|r| &r.outcome) {
            let (angle, dist) = out.t_sensor_target.error_to(&truth.t_sensor_target);
            println!(
                "  reported pose: {:.2} deg {:.3} m off",
                angle.to_degrees(),
                dist
            );
        }
        if msg.success == 1 {
            successes += 1;
            assert_eq!(msg.method, AcquisitionMethod::TemplateMatching as u8);
            let (angle, dist) = msg.pose().unwrap().error_to(&truth.t_sensor_target);
            println!(
                "  error {:.2} deg {:.3} m, {:.0} ms",
                angle.to_degrees(),
                dist,
                msg.time_ms
            );
            // deos has a 180° symmetry about its roll axis at most; an
            // accepted pose must be close to the truth or to that twin.
            assert!(dist < 0.3, "accepted pose {dist} m off");
        }
    }
    assert!(successes >= 2, "{successes} of 3 frames acquired");
}

/// Seed 002 §4.5's failure cases: no false success, no panic.
#[test]
fn sparse_and_all_outlier_clouds_are_failures() {
    let chain = config().build_chain().unwrap();
    let instance = Name::new("init").unwrap();

    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let sparse: Vec<Point> = (0..19)
        .map(|_| Point::new(rng.random_range(-1.0..1.0), 0.0, 15.0, 1.0, 0.0))
        .collect();
    // Outliers only: points spread over a 6 m cube around 15 m, nothing of
    // the target's shape.
    let outliers: Vec<Point> = (0..3000)
        .map(|_| {
            Point::new(
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
                rng.random_range(12.0..18.0),
                1.0,
                0.0,
            )
        })
        .collect();
    for (what, cloud) in [("sparse", sparse), ("all-outlier", outliers)] {
        let a = chain.acquire(&cloud);
        println!("{what}: {}", a.summary());
        let msg = a.to_wire(1, 1.0, instance);
        assert_eq!(msg.success, 0, "{what} cloud gave a success");
    }
}
