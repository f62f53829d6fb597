//! End-to-end tests of the simulator on the built-in `deos` target.

use crate::{Effects, Frame, LidarSimulator, ReturnKind, SensorConfig, SimError, SurfaceModel};
use nalgebra::{Rotation3, Vector3};
use spacepose_geometry::{Point, Pose};
use spacepose_model::Target;
use spacepose_scenario::TruthState;
use std::sync::{Arc, OnceLock};

fn deos() -> Arc<Target> {
    static DEOS: OnceLock<Arc<Target>> = OnceLock::new();
    DEOS.get_or_init(|| Arc::new(Target::builtin("deos").unwrap()))
        .clone()
}

/// An oblique view of the target (side panels, one MLI end face and the tower visible).
fn attitude() -> Rotation3<f64> {
    Rotation3::from_euler_angles(0.3, 0.5, 0.8)
}

fn truth(range_m: f64, v: Vector3<f64>, w: Vector3<f64>) -> TruthState {
    TruthState {
        t: 100.0,
        t_sensor_target: Pose::new(attitude(), Vector3::new(0.0, 0.0, range_m)),
        v_sensor_target: v,
        w_target: w,
    }
}

fn static_truth() -> TruthState {
    truth(10.0, Vector3::zeros(), Vector3::zeros())
}

fn tumbling_truth() -> TruthState {
    // 10°/s about an oblique body axis, 3 cm/s drift.
    let w = Vector3::new(0.3, 1.0, 0.5).normalize() * 10f64.to_radians();
    truth(10.0, Vector3::new(0.02, -0.01, 0.02), w)
}

fn sim(effects: Effects) -> LidarSimulator {
    let config = SensorConfig {
        effects,
        ..SensorConfig::livox_mid40()
    };
    LidarSimulator::new(deos(), config).unwrap()
}

fn run(sim: &LidarSimulator, truth: &TruthState, seed: u64) -> Frame {
    sim.simulate(truth, &mut LidarSimulator::frame_rng(seed, 0))
}

/// Distance of a sensor-frame point to the mesh at the scan-end pose.
fn residual(truth: &TruthState, p: &Point) -> f64 {
    let body = truth.t_sensor_target.inverse().transform(&p.position());
    deos().mesh().distance_to_surface(&body)
}

fn rms(truth: &TruthState, frame: &Frame) -> f64 {
    let n = frame.points.len() as f64;
    (frame
        .points
        .iter()
        .map(|p| residual(truth, p).powi(2))
        .sum::<f64>()
        / n)
        .sqrt()
}

fn count(frame: &Frame, kind: ReturnKind) -> usize {
    frame.kinds.iter().filter(|&&k| k == kind).count()
}

/// Random attitudes (uniform quaternions) for point-count statistics.
fn random_attitudes(n: usize, seed: u64) -> Vec<Rotation3<f64>> {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let q = nalgebra::Quaternion::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            nalgebra::UnitQuaternion::from_quaternion(q).to_rotation_matrix()
        })
        .collect()
}

/// Mean point count of a deos frame at 10 m over random attitudes.
fn mean_count(effects: Effects, attitudes: &[Rotation3<f64>]) -> f64 {
    let s = sim(effects);
    let counts: Vec<usize> = attitudes
        .iter()
        .enumerate()
        .map(|(k, r)| {
            let mut t = static_truth();
            t.t_sensor_target.rotation = *r;
            let frame = run(&s, &t, 100 + k as u64);
            assert!(
                frame
                    .points
                    .iter()
                    .all(|p| p.is_finite() && p.intensity >= 0.0)
            );
            assert_eq!(count(&frame, ReturnKind::Clutter), 0);
            frame.points.len()
        })
        .collect();
    let (min, max) = (counts.iter().min().unwrap(), counts.iter().max().unwrap());
    println!("{effects:?}: counts from {min} to {max}");
    counts.iter().sum::<usize>() as f64 / attitudes.len() as f64
}

#[test]
fn default_frame_has_about_ten_thousand_points_at_10_m() {
    let attitudes = random_attitudes(16, 11);
    let with_effects = mean_count(Effects::default(), &attitudes);
    let geometric = mean_count(Effects::none(), &attitudes);
    println!(
        "deos at 10 m, {} s, mean over 16 attitudes: {with_effects:.0} points (default effects), {geometric:.0} (no effect)",
        SensorConfig::MID40_INTEGRATION_TIME_S
    );
    assert!(
        (8_500.0..=11_500.0).contains(&with_effects),
        "{with_effects}"
    );
    assert!(geometric > with_effects);
}

#[test]
fn without_effects_every_point_lies_on_the_mesh() {
    let truth = static_truth();
    let frame = run(&sim(Effects::none()), &truth, 2);
    let n = frame.points.len();
    println!("deos at 10 m, no effect: {n} points");
    // 54,000 rays in the default 0.54 s scan; about a fifth hit the target.
    assert!((9_000..=15_000).contains(&n), "{n} points");
    let inv = truth.t_sensor_target.inverse();
    for p in &frame.points {
        // Cast the true ray again at the end pose: the range must match.
        let x = p.position();
        let dir = x.normalize();
        let hit = deos()
            .cast_ray(&inv.translation, &(inv.rotation * dir), 100.0)
            .unwrap();
        assert!(
            (hit.distance - x.norm()).abs() < 1e-4,
            "{} vs {}",
            hit.distance,
            x.norm()
        );
        assert!(residual(&truth, p) < 1e-4);
    }
    assert!(frame.kinds.iter().all(|&k| k == ReturnKind::Target));
}

#[test]
fn tumbling_frame_is_blurred() {
    let (still, moving) = (static_truth(), tumbling_truth());
    let ideal = sim(Effects {
        motion_blur: true,
        ..Effects::none()
    });
    let rms_still = rms(&still, &run(&ideal, &still, 3));
    let rms_blur = rms(&moving, &run(&ideal, &moving, 3));
    println!(
        "no noise: RMS residual at the end pose, still {rms_still:.2e} m, 10°/s {rms_blur:.4} m"
    );
    assert!(
        rms_still < 1e-4 && rms_blur > 0.01,
        "{rms_still} {rms_blur}"
    );
    // With Gaussian range and line-of-sight noise on top.
    let noisy = sim(Effects {
        motion_blur: true,
        range_noise: true,
        los_noise: true,
        ..Effects::none()
    });
    let rms_still = rms(&still, &run(&noisy, &still, 3));
    let rms_blur = rms(&moving, &run(&noisy, &moving, 3));
    println!(
        "range + LOS noise: RMS residual at the end pose, still {rms_still:.4} m, 10°/s {rms_blur:.4} m"
    );
    assert!(rms_blur > 1.2 * rms_still, "{rms_still} {rms_blur}");
    // With every effect, the reflection and divergence artefacts dominate the RMS (reported only).
    let full = sim(Effects::default());
    let rms_still = rms(&still, &run(&full, &still, 3));
    let rms_blur = rms(&moving, &run(&full, &moving, 3));
    println!(
        "all effects: RMS residual at the end pose, still {rms_still:.4} m, 10°/s {rms_blur:.4} m"
    );
    // Switching blur off puts the target at its end pose for every ray.
    let unblurred = run(&sim(Effects::none()), &moving, 3);
    assert!(rms(&moving, &unblurred) < 1e-4);
}

#[test]
fn timestamps_lie_in_the_window_in_scan_order() {
    let frame = run(&sim(Effects::default()), &tumbling_truth(), 4);
    assert!((frame.scan_end - 100.0).abs() < 1e-12);
    assert!(
        (frame.scan_end - frame.scan_start - SensorConfig::MID40_INTEGRATION_TIME_S).abs() < 1e-12
    );
    let mut last = f64::NEG_INFINITY;
    for p in &frame.points {
        assert!(p.t >= frame.scan_start && p.t <= frame.scan_end && p.t >= last);
        last = p.t;
    }
    let spread = frame.points.last().unwrap().t - frame.points[0].t;
    assert!(spread > 0.5 * SensorConfig::MID40_INTEGRATION_TIME_S);
}

#[test]
fn outlier_fraction_matches_the_configuration() {
    let config = SensorConfig {
        effects: Effects {
            outliers: true,
            ..Effects::none()
        },
        integration_time_s: 2.0,
        ..SensorConfig::livox_mid40()
    };
    let sim = LidarSimulator::new(deos(), config).unwrap();
    let truth = static_truth();
    let frame = run(&sim, &truth, 5);
    let n = frame.points.len();
    let frac = count(&frame, ReturnKind::Outlier) as f64 / n as f64;
    println!("outliers: {frac:.4} of {n} points (configured 0.05)");
    assert!(n > 40_000 && (frac - 0.05).abs() < 0.005, "{frac} of {n}");
    // Outliers are off the surface by 4 σ_RANGE = 8 cm RMS (along the ray).
    let off: Vec<f64> = frame
        .points
        .iter()
        .zip(&frame.kinds)
        .filter(|(_, k)| **k == ReturnKind::Outlier)
        .map(|(p, _)| residual(&truth, p))
        .collect();
    let mean_off = off.iter().sum::<f64>() / off.len() as f64;
    assert!(mean_off > 0.02, "{mean_off}");
}

#[test]
fn clutter_is_off_by_default_and_tagged_when_on() {
    let truth = static_truth();
    let quiet = run(&sim(Effects::default()), &truth, 6);
    assert_eq!(count(&quiet, ReturnKind::Clutter), 0);
    let busy = run(&sim(Effects::all()), &truth, 6);
    let clutter = count(&busy, ReturnKind::Clutter);
    let target = count(&busy, ReturnKind::Target);
    println!("with clutter: {clutter} clutter points, {target} target points");
    assert!(clutter > 1000 && target > 5000);
    // Clutter points are away from the target (the arm touches it from below).
    let far = busy
        .points
        .iter()
        .zip(&busy.kinds)
        .filter(|(p, k)| **k == ReturnKind::Clutter && residual(&truth, p) > 0.1)
        .count();
    assert!(far as f64 > 0.95 * clutter as f64);
}

#[test]
fn detection_drops_points_and_divergence_and_reflections_add_artefacts() {
    let truth = static_truth();
    let ideal = run(&sim(Effects::none()), &truth, 7);
    let detected = run(
        &sim(Effects {
            detection: true,
            reflections: true,
            ..Effects::none()
        }),
        &truth,
        7,
    );
    assert!(detected.points.len() < ideal.points.len());
    let off = |frame: &Frame| {
        frame
            .points
            .iter()
            .filter(|p| residual(&truth, p) > 0.02)
            .count()
    };
    let diverged = run(
        &sim(Effects {
            beam_divergence: true,
            ..Effects::none()
        }),
        &truth,
        7,
    );
    let reflected = run(
        &sim(Effects {
            reflections: true,
            ..Effects::none()
        }),
        &truth,
        7,
    );
    println!(
        "points > 2 cm off the surface: ideal {}, divergence {}, reflections {} (of {})",
        off(&ideal),
        off(&diverged),
        off(&reflected),
        reflected.points.len()
    );
    assert_eq!(off(&ideal), 0);
    assert!(off(&diverged) > 0 && off(&reflected) > 0);
}

#[test]
fn frame_streams_are_reproducible_and_independent() {
    let s = sim(Effects::default());
    let truth = tumbling_truth();
    let a = s.simulate(&truth, &mut LidarSimulator::frame_rng(9, 3));
    let b = s.simulate(&truth, &mut LidarSimulator::frame_rng(9, 3));
    let c = s.simulate(&truth, &mut LidarSimulator::frame_rng(9, 4));
    assert_eq!(a, b);
    assert_ne!(a.points, c.points);
}

#[test]
fn raster_sensor_gives_a_sparse_cloud_and_rejects_bad_truth() {
    let envisat = Arc::new(Target::builtin("envisat").unwrap());
    let sim = LidarSimulator::new(envisat, SensorConfig::raster_seed002()).unwrap();
    let frame = run(&sim, &truth(30.0, Vector3::zeros(), Vector3::zeros()), 10);
    println!(
        "envisat at 30 m, seed-002 raster: {} points",
        frame.points.len()
    );
    assert!(frame.points.len() > 50 && frame.points.len() < 41 * 41);
    assert!((frame.scan_end - frame.scan_start - crate::RASTER_SCAN_TIME_S).abs() < 1e-12);
    let mut bad = static_truth();
    bad.v_sensor_target.x = f64::NAN;
    let mut rng = LidarSimulator::frame_rng(0, 0);
    assert!(matches!(
        sim.try_simulate(&bad, &mut rng),
        Err(SimError::NonFiniteTruth(_))
    ));
    assert!(sim.simulate(&bad, &mut rng).points.is_empty());
}

/// Seed 002's raster with its Lambertian return keeps most of ENVISAT's
/// geometric points at 50 m (the paper: ~120 points there), where seed 004's
/// specular solar array would vanish.
#[test]
fn seed002_raster_sees_the_solar_array_at_50_m() {
    let envisat = Arc::new(Target::builtin("envisat").unwrap());
    let count = |surface_model: SurfaceModel, effects: Effects| {
        let config = SensorConfig {
            surface_model,
            effects,
            ..SensorConfig::raster_seed002()
        };
        let sim = LidarSimulator::new(envisat.clone(), config).unwrap();
        (0..8u64)
            .map(|k| {
                let a = k as f64;
                let truth = TruthState {
                    t: 100.0,
                    t_sensor_target: Pose::new(
                        Rotation3::from_euler_angles(0.7 * a, 0.4 * a - 1.2, 1.1 * a),
                        Vector3::new(0.0, 0.0, 50.0),
                    ),
                    v_sensor_target: Vector3::zeros(),
                    w_target: Vector3::zeros(),
                };
                run(&sim, &truth, k).points.len()
            })
            .sum::<usize>()
    };
    let ideal = count(SurfaceModel::Lambertian, Effects::none());
    let lambertian = count(SurfaceModel::Lambertian, Effects::default());
    let phong = count(SurfaceModel::Phong, Effects::default());
    println!("envisat at 50 m, 8 attitudes: ideal {ideal}, Lambertian {lambertian}, Phong {phong}");
    assert!(lambertian as f64 > 0.85 * ideal as f64);
    assert!((phong as f64) < 0.75 * lambertian as f64);
    assert_eq!(
        SensorConfig::raster_seed002().surface_model,
        SurfaceModel::Lambertian
    );
    assert_eq!(
        SensorConfig::livox_mid40().surface_model,
        SurfaceModel::Phong
    );
}

#[test]
fn invalid_configuration_is_rejected() {
    let config = SensorConfig {
        integration_time_s: f64::NAN,
        ..SensorConfig::livox_mid40()
    };
    assert!(LidarSimulator::new(deos(), config).is_err());
}

#[test]
fn frames_looking_away_see_no_target_and_the_others_do() {
    use spacepose_scenario::{LookAway, ScenarioConfig, ScenarioKind};
    let look = LookAway::frames(2, 3);
    let scenario = spacepose_scenario::build(&ScenarioConfig {
        seed: 7,
        look_away: Some(look),
        ..ScenarioConfig::default_for(ScenarioKind::Tumbling)
    })
    .unwrap();
    let s = sim(Effects::default());
    let mut counts = Vec::new();
    for (k, t) in scenario.frame_end_times(7).into_iter().enumerate() {
        let frame = s.simulate(
            &scenario.state_at(t),
            &mut LidarSimulator::frame_rng(7, k as u64),
        );
        counts.push(frame.points.len());
    }
    println!("points per frame, frames 2-4 looking away: {counts:?}");
    for (k, n) in counts.iter().enumerate() {
        if look.covers_frame(k) {
            assert_eq!(*n, 0, "frame {k}");
        } else {
            assert!(*n > 1000, "frame {k}: {n} points");
        }
    }
}
