//! Tracking-loop tests on simulated `deos` frames (Livox Mid-40 model, every
//! sensor effect on, 1 s integration at 1 Hz) with known ground truth.
//! Seeds used here are test seeds, not the evaluation's.

use crate::{TrackStatus, Tracker, TrackerConfig, TrackingMode, TrackingModel};
use nalgebra::Vector3;
use spacepose_lidar_sim::{LidarSimulator, SensorConfig};
use spacepose_registration::NdtMapParams;
use spacepose_scenario::{ScenarioConfig, ScenarioKind, build};
use spacepose_target::Target;
use std::sync::{Arc, OnceLock};

fn deos() -> &'static (Arc<Target>, TrackingModel) {
    static F: OnceLock<(Arc<Target>, TrackingModel)> = OnceLock::new();
    F.get_or_init(|| {
        let target = Arc::new(Target::builtin("deos").unwrap());
        let model =
            TrackingModel::build(&target.sample_surface(0.015, 0), &NdtMapParams::default())
                .unwrap();
        (target, model)
    })
}

/// Runs `modes` over `frames` frames of `kind` from frame `first`; returns
/// (status, angular error deg, position error m) per mode and frame.
fn run(
    kind: ScenarioKind,
    modes: &[TrackingMode],
    first: usize,
    frames: usize,
    seed: u64,
) -> Vec<Vec<(TrackStatus, f64, f64)>> {
    let (target, model) = deos();
    let mut config = ScenarioConfig::default_for(kind);
    config.seed = seed;
    let scenario = build(&config).unwrap();
    let mut sensor = SensorConfig::livox_mid40();
    sensor.integration_time_s = 1.0;
    let sim = LidarSimulator::new(target.clone(), sensor).unwrap();
    let ends = scenario.frame_end_times(first + frames);
    let t0 = ends[first] - 1.0;
    let mut trackers: Vec<Tracker> = modes
        .iter()
        .map(|&m| {
            let mut t = Tracker::new(TrackerConfig::with_mode(m), model.clone()).unwrap();
            t.initialize(
                t0,
                &scenario.pose_at(t0),
                Vector3::zeros(),
                Vector3::zeros(),
            )
            .unwrap();
            t
        })
        .collect();
    let mut results = vec![Vec::new(); modes.len()];
    for (k, &t_end) in ends.iter().enumerate().skip(first) {
        let frame = sim.simulate(
            &scenario.state_at(t_end),
            &mut LidarSimulator::frame_rng(seed, k as u64),
        );
        for (tracker, res) in trackers.iter_mut().zip(results.iter_mut()) {
            let out = tracker
                .process(&frame.points, frame.scan_start, frame.scan_end)
                .unwrap();
            let (ang, pos) = out.t_sensor_target.error_to(&frame.truth.t_sensor_target);
            res.push((out.status, ang.to_degrees(), pos));
        }
    }
    results
}

#[test]
fn every_mode_tracks_the_slow_spin_inspection() {
    let results = run(ScenarioKind::SlowSpin, &TrackingMode::ALL, 0, 12, 11);
    for (mode, res) in TrackingMode::ALL.iter().zip(&results) {
        for (k, (status, ang, pos)) in res.iter().enumerate() {
            assert_ne!(*status, TrackStatus::Lost, "{mode} frame {k}");
            assert!(
                *ang < 3.0 && *pos < 0.08,
                "{mode} frame {k}: {ang:.2} deg, {pos:.3} m"
            );
        }
    }
}

#[test]
fn deblur_and_ct_ndt_track_a_10_degps_tumble() {
    let modes = [TrackingMode::Deblur, TrackingMode::CtNdt];
    let results = run(ScenarioKind::Tumbling, &modes, 0, 20, 12);
    for (mode, res) in modes.iter().zip(&results) {
        for (k, (status, ang, pos)) in res.iter().enumerate() {
            assert_ne!(*status, TrackStatus::Lost, "{mode} frame {k}");
            // The filter starts at ω = 0 and learns the 10°/s within the
            // evaluation's 10 warm-up frames (seed 000 §5.2).
            let limit = if k < 10 { 10.0 } else { 3.0 };
            assert!(
                *ang < limit && *pos < 0.1,
                "{mode} frame {k}: {ang:.2} deg, {pos:.3} m"
            );
        }
    }
}
