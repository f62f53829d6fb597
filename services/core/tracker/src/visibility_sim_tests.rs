//! The visibility gate on simulated frames with known truth: development
//! design `zoo:1001` (a box bus with a boom and a dish, MLI-covered),
//! tumbling scenario seed 2023, frames where the reflections add thousands
//! of ghosts (the frames where every development design lost the track).

use crate::visibility::{VisibilityConfig, VisibilityModel};
use nalgebra::{Matrix6, Rotation3, Vector3};
use spacepose_filter::Prediction;
use spacepose_geometry::Pose;
use spacepose_lidar_sim::{LidarSimulator, SensorConfig};
use spacepose_scenario::{ScenarioConfig, ScenarioKind, build};
use std::sync::Arc;

/// A prediction at `pose`, at rest (the frames are simulated without
/// motion blur, so every point is at the scan-end pose).
fn prediction(t: f64, pose: Pose) -> Prediction {
    Prediction {
        t,
        pose,
        v_sensor: Vector3::zeros(),
        w_target: Vector3::zeros(),
        w_inertial_sensor: nalgebra::Vector3::zeros(),
        covariance: Matrix6::identity() * 1e-8,
        attitude_covariance: spacepose_filter::Matrix9::identity() * 1e-8,
        position_covariance: Matrix6::identity() * 1e-8,
    }
}

#[test]
fn the_gate_drops_the_reflection_ghosts_and_hardly_any_surface_return() {
    let target = Arc::new(spacepose_model::zoo::generate(1001).unwrap().target);
    let mut config = ScenarioConfig::default_for(ScenarioKind::Tumbling);
    config.seed = 2023;
    let scenario = build(&config).unwrap();
    let simulator = |reflections: bool| {
        let mut sensor = SensorConfig::livox_mid40();
        sensor.integration_time_s = 1.0;
        sensor.effects.motion_blur = false;
        sensor.effects.reflections = reflections;
        LidarSimulator::new(target.clone(), sensor).unwrap()
    };
    let (with, without) = (simulator(true), simulator(false));
    // The tracker's model cloud and thinning for this design: 1.5 cm and a
    // third of the 7.5 cm cell, both times ℓ / 7.5 cm (ℓ = 0.018 √A, about
    // 0.22 m).
    let model = VisibilityModel::new(&target.sample_surface(0.044, 0), 0.073);
    let ends = scenario.frame_end_times(81);
    for k in [49, 55, 80] {
        let state = scenario.state_at(ends[k]);
        let truth = state.t_sensor_target;
        // The prediction 2° off the truth, twice the default allowance.
        let off = Rotation3::from_axis_angle(&Vector3::y_axis(), 2f64.to_radians());
        let pose = Pose::new(off * truth.rotation, truth.translation);
        let gate = |sim: &LidarSimulator| {
            let frame = sim.simulate(&state, &mut LidarSimulator::frame_rng(2023, k as u64));
            let n = frame.points.len();
            let g = model
                .gate(
                    frame.points,
                    true,
                    &prediction(ends[k], pose),
                    &VisibilityConfig::default(),
                )
                .unwrap();
            assert!(!g.overruled);
            (n, g.behind)
        };
        let (n_with, dropped_with) = gate(&with);
        let (n_without, dropped_without) = gate(&without);
        let ghosts = n_with - n_without;
        assert!(
            dropped_with as f64 >= 0.7 * ghosts as f64,
            "frame {k}: {dropped_with} dropped of about {ghosts} ghosts"
        );
        assert!(
            dropped_without as f64 <= 0.02 * n_without as f64,
            "frame {k}: {dropped_without} of {n_without} surface returns dropped"
        );
    }
}
