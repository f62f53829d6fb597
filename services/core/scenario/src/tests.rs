//! Scenario-level tests: distances, rates, consistency of v and ω with the
//! pose, compression, determinism.

use crate::presets::{self, tumbling_body};
use crate::relative::RelativeMotion;
use crate::{Scenario, ScenarioConfig, ScenarioError, ScenarioKind, build, random_frame_euler};
use nalgebra::Vector3;
use spacepose_geometry::{Euler321, so3};

fn scenario(kind: ScenarioKind, compression: f64) -> Box<dyn Scenario> {
    build(&ScenarioConfig {
        compression,
        seed: 7,
        ..ScenarioConfig::default_for(kind)
    })
    .unwrap()
}

fn relative(kind: ScenarioKind, compression: f64) -> RelativeMotion {
    let cfg = ScenarioConfig {
        compression,
        seed: 7,
        ..ScenarioConfig::default_for(kind)
    };
    match kind {
        ScenarioKind::SlowSpin => presets::slow_spin(&cfg),
        ScenarioKind::Tumbling => presets::tumbling(&cfg),
        ScenarioKind::Ellipse => presets::ellipse(&cfg),
        ScenarioKind::Random => panic!("not a continuous scenario"),
    }
}

fn range(s: &dyn Scenario, t: f64) -> f64 {
    s.pose_at(t).translation.norm()
}

const CONTINUOUS: [ScenarioKind; 3] = [
    ScenarioKind::SlowSpin,
    ScenarioKind::Tumbling,
    ScenarioKind::Ellipse,
];

#[test]
fn every_scenario_gives_finite_states_over_its_frames() {
    for kind in ScenarioKind::ALL {
        let s = scenario(kind, 1.0);
        let times = s.frame_end_times(s.natural_frame_count());
        assert!(!times.is_empty());
        for t in times.iter().step_by(7) {
            let state = s.state_at(*t);
            assert!(state.is_finite(), "{kind} at {t}: {state:?}");
            assert_eq!(state.t, *t);
            assert!(
                state.t_sensor_target.translation.z > 0.0,
                "{kind}: target behind the sensor"
            );
            let pose = s.pose_at(*t);
            assert!(pose.error_to(&state.t_sensor_target).0 < 1e-12);
        }
    }
}

#[test]
fn frame_end_times_start_one_period_in() {
    let s = scenario(ScenarioKind::Ellipse, 1.0);
    assert_eq!(s.frame_period_s(), 50.0);
    let times = s.frame_end_times(241);
    assert_eq!(times.len(), 241);
    assert_eq!(times[0], 50.0);
    assert!(times.windows(2).all(|w| (w[1] - w[0] - 50.0).abs() < 1e-9));
    assert!((times[240] - 50.0 - s.duration_s()).abs() < 1e-6);
}

#[test]
fn slow_spin_distances_follow_seed_000() {
    let s = scenario(ScenarioKind::SlowSpin, 1.0);
    assert!((s.duration_s() - 1470.0).abs() < 1e-9);
    for t in (0..=550).step_by(5) {
        assert!((range(&*s, t as f64) - 15.0).abs() < 1e-9, "t={t}");
    }
    for t in 900..=970 {
        assert!((range(&*s, t as f64) - 8.0).abs() < 1e-9, "t={t}");
    }
    assert!((range(&*s, 1470.0) - 3.0).abs() < 1e-9);
    // Mid-approach speeds: 2 cm/s then 1 cm/s (slightly more for the ramps).
    let v1 = s
        .state_at(725.0)
        .t_sensor_target
        .translation
        .normalize()
        .dot(&s.state_at(725.0).v_sensor_target);
    let v2 = s
        .state_at(1220.0)
        .t_sensor_target
        .translation
        .normalize()
        .dot(&s.state_at(1220.0).v_sensor_target);
    assert!((v1 + 7.0 / 340.0).abs() < 1e-6, "{v1}");
    assert!((v2 + 5.0 / 490.0).abs() < 1e-6, "{v2}");
    // The inspection sees the target from well off the hold axis.
    let m = relative(ScenarioKind::SlowSpin, 1.0);
    let widest = (0..500)
        .map(|t| {
            (m.sensor_in_lvlh(t as f64) * Vector3::z())
                .angle(&-Vector3::y())
                .to_degrees()
        })
        .fold(0.0, f64::max);
    assert!(widest > 70.0, "{widest}");
}

#[test]
fn slow_spin_target_turns_at_one_degree_per_second_about_y_lvlh() {
    let m = relative(ScenarioKind::SlowSpin, 1.0);
    let (r0, _) = m.target_in_lvlh(100.0);
    let (r1, _) = m.target_in_lvlh(110.0);
    let turn = so3::log(&(r1 * r0.inverse()));
    assert!((turn - Vector3::y() * 10f64.to_radians()).norm() < 1e-12);
    // Body x (roll axis) stays on y_LVLH.
    assert!((r1 * Vector3::x() - Vector3::y()).norm() < 1e-12);
}

#[test]
fn tumbling_spin_rate_and_axis_tilt_follow_seed_000() {
    let s = scenario(ScenarioKind::Tumbling, 1.0);
    assert!((s.duration_s() - 1380.0).abs() < 1e-9);
    // During the 8 m hold only the pointing error turns the sensor.
    for t in 700..750 {
        let w = s.state_at(t as f64).w_target.norm().to_degrees();
        assert!((w - 101f64.sqrt()).abs() < 0.05, "t={t}: {w} deg/s");
    }
    let m = relative(ScenarioKind::Tumbling, 1.0);
    let mut max_tilt: f64 = 0.0;
    let mut min_tilt: f64 = 180.0;
    for i in 0..1200 {
        let (r, w) = m.target_in_lvlh(i as f64 * 0.05);
        assert!((w.norm().to_degrees() - 101f64.sqrt()).abs() < 1e-9);
        let tilt = (r * Vector3::x()).angle(&Vector3::y()).to_degrees();
        max_tilt = max_tilt.max(tilt);
        min_tilt = min_tilt.min(tilt);
    }
    assert!((max_tilt - 10.0).abs() < 0.01, "{max_tilt}");
    assert!(min_tilt < 1.0, "{min_tilt}");
    for (t, want) in [
        (0.0, 15.0),
        (350.0, 15.0),
        (700.0, 8.0),
        (1150.0, 4.0),
        (1200.0, 4.0),
        (1380.0, 3.0),
    ] {
        assert!((range(&*s, t) - want).abs() < 1e-9, "t={t}");
    }
}

#[test]
fn tumbling_figures() {
    let body = tumbling_body(0.0);
    let deg = |x: f64| x.to_degrees();
    assert!((deg(body.nutation_angle()) - 4.7636).abs() < 1e-3);
    assert!((deg(body.space_precession_rate()) - (144.0f64 + 1.0).sqrt()).abs() < 1e-9);
    assert!((deg(body.body_precession_rate()) - 2.0).abs() < 1e-9);
}

#[test]
fn ellipse_ranges_from_25_to_53_m_over_241_frames() {
    let s = scenario(ScenarioKind::Ellipse, 1.0);
    assert_eq!(s.natural_frame_count(), 241);
    let times = s.frame_end_times(241);
    let ranges: Vec<f64> = times.iter().map(|t| range(&*s, *t)).collect();
    let min = ranges.iter().copied().fold(f64::INFINITY, f64::min);
    let max = ranges.iter().copied().fold(0.0, f64::max);
    assert!(
        (min - 25.0).abs() < 0.05 && (max - 53.0).abs() < 0.05,
        "{min} {max}"
    );
    // Consecutive frames see strongly different attitudes.
    let mean_turn = times
        .windows(2)
        .map(|w| so3::distance(&s.pose_at(w[0]).rotation, &s.pose_at(w[1]).rotation).to_degrees())
        .sum::<f64>()
        / 240.0;
    assert!(mean_turn > 45.0, "{mean_turn}");
}

#[test]
fn random_frames_have_the_range_and_open_euler_intervals() {
    let cfg = ScenarioConfig {
        range_m: 30.0,
        seed: 3,
        ..ScenarioConfig::default_for(ScenarioKind::Random)
    };
    let s = build(&cfg).unwrap();
    assert_eq!(s.natural_frame_count(), 500);
    let mut yaw_span = (0.0f64, 0.0f64);
    for (k, t) in s.frame_end_times(500).into_iter().enumerate() {
        let state = s.state_at(t);
        assert!((state.t_sensor_target.translation.norm() - 30.0).abs() < 1e-9);
        let p = state.t_sensor_target.translation;
        assert!((p.x / p.z).atan().abs() <= 1f64.to_radians() + 1e-12);
        assert_eq!(state.v_sensor_target, Vector3::zeros());
        assert_eq!(state.w_target, Vector3::zeros());
        let e = Euler321::from_rotation(&state.t_sensor_target.rotation);
        let drawn = random_frame_euler(3, k as u64);
        assert!((e.yaw - drawn.yaw).abs() < 1e-9 && (e.pitch - drawn.pitch).abs() < 1e-9);
        let [y, p, r] = drawn.to_degrees();
        assert!(y > -180.0 && y < 180.0 && p > -90.0 && p < 90.0 && r > -180.0 && r < 180.0);
        yaw_span = (yaw_span.0.min(y), yaw_span.1.max(y));
        // Constant over the scan that ends at t.
        assert_eq!(
            s.pose_at(t - 0.99 * cfg.frame_period_s),
            state.t_sensor_target
        );
    }
    assert!(yaw_span.0 < -170.0 && yaw_span.1 > 170.0, "{yaw_span:?}");
    // Frame k depends only on (seed, k).
    let other = build(&ScenarioConfig {
        random_frames: 10,
        range_m: 30.0,
        ..cfg.clone()
    })
    .unwrap();
    assert_eq!(other.pose_at(100.0).rotation, s.pose_at(100.0).rotation);
    let reseeded = build(&ScenarioConfig { seed: 4, ..cfg }).unwrap();
    assert_ne!(reseeded.pose_at(100.0).rotation, s.pose_at(100.0).rotation);
}

/// Five-point finite differences of the pose (error O(h⁴)): translation
/// `p(t + τ)` and rotation `Log(R(t)ᵀ R(t + τ))`, both with derivative
/// `(v, ω)` at τ = 0.
fn finite_difference(s: &dyn Scenario, t: f64, h: f64) -> (Vector3<f64>, Vector3<f64>) {
    let base = s.pose_at(t).rotation.inverse();
    let sample = |tau: f64| {
        let pose = s.pose_at(t + tau);
        (pose.translation, so3::log(&(base * pose.rotation)))
    };
    let stencil = |f: &dyn Fn(f64) -> Vector3<f64>| {
        (f(h) - f(-h)) * (8.0 / (12.0 * h)) - (f(2.0 * h) - f(-2.0 * h)) / (12.0 * h)
    };
    (stencil(&|tau| sample(tau).0), stencil(&|tau| sample(tau).1))
}

#[test]
fn velocities_match_finite_differences_of_the_pose() {
    for kind in CONTINUOUS {
        for compression in [1.0, 70.0] {
            let s = scenario(kind, compression);
            let h = 1e-3 / compression;
            let mut worst: f64 = 0.0;
            let n = 97;
            for i in 0..n {
                let t = 0.5 + (s.duration_s() + s.frame_period_s()) * i as f64 / n as f64;
                let state = s.state_at(t);
                let (v_fd, w_fd) = finite_difference(&*s, t, h);
                let ev =
                    (state.v_sensor_target - v_fd).norm() / state.v_sensor_target.norm().max(1e-6);
                let ew = (state.w_target - w_fd).norm() / state.w_target.norm();
                worst = worst.max(ev).max(ew);
                assert!(
                    ev < 1e-6,
                    "{kind} x{compression} t={t}: v {:?} vs {v_fd:?}",
                    state.v_sensor_target
                );
                assert!(
                    ew < 1e-6,
                    "{kind} x{compression} t={t}: w {:?} vs {w_fd:?}",
                    state.w_target
                );
                // w_sensor is the same rate seen from the sensor.
                let w_s =
                    so3::log(&(s.pose_at(t + h).rotation * s.pose_at(t - h).rotation.inverse()))
                        / (2.0 * h);
                assert!((state.w_sensor() - w_s).norm() < 1e-6 * w_s.norm());
            }
            eprintln!("{kind} x{compression}: worst relative error of v, ω: {worst:.1e}");
        }
    }
}

#[test]
fn compression_shortens_the_trajectory_but_keeps_the_spin() {
    for kind in CONTINUOUS {
        let slow = scenario(kind, 1.0);
        let fast = scenario(kind, 70.0);
        assert!((slow.duration_s() / fast.duration_s() - 70.0).abs() < 1e-9);
        for i in 0..40 {
            let t = slow.duration_s() * i as f64 / 39.0;
            assert!((range(&*slow, t) - range(&*fast, t / 70.0)).abs() < 1e-9);
        }
    }
    // Whole slow-spin approach in 22 frames of 1 s.
    assert_eq!(
        scenario(ScenarioKind::SlowSpin, 70.0).natural_frame_count(),
        22
    );
    for kind in [ScenarioKind::SlowSpin, ScenarioKind::Tumbling] {
        let (slow, fast) = (relative(kind, 1.0), relative(kind, 70.0));
        for t in [0.0, 3.0, 17.5] {
            let (a, wa) = slow.target_in_lvlh(t);
            let (b, wb) = fast.target_in_lvlh(t);
            assert!(so3::distance(&a, &b) < 1e-12 && (wa - wb).norm() < 1e-15);
        }
    }
}

#[test]
fn pointing_error_keeps_the_target_near_but_off_the_boresight() {
    for kind in CONTINUOUS {
        let s = scenario(kind, 1.0);
        let mut worst: f64 = 0.0;
        for t in s.frame_end_times(s.natural_frame_count()) {
            let off = s.pose_at(t).translation.angle(&Vector3::z()).to_degrees();
            assert!(off <= 0.3 * 2f64.sqrt() + 1e-9, "{kind} t={t}: {off}");
            worst = worst.max(off);
        }
        assert!(worst > 0.15, "{kind}: {worst}");
    }
    let exact = build(&ScenarioConfig {
        pointing_error_deg: 0.0,
        ..ScenarioConfig::default_for(ScenarioKind::Tumbling)
    })
    .unwrap();
    assert!(exact.pose_at(400.0).translation.angle(&Vector3::z()) < 1e-12);
}

#[test]
fn scenarios_are_deterministic_given_the_seed() {
    for kind in ScenarioKind::ALL {
        let a = scenario(kind, 1.0).state_at(123.4);
        let b = scenario(kind, 1.0).state_at(123.4);
        assert_eq!(a, b);
        let c = build(&ScenarioConfig {
            seed: 8,
            ..ScenarioConfig::default_for(kind)
        })
        .unwrap()
        .state_at(123.4);
        assert_ne!(a.t_sensor_target, c.t_sensor_target, "{kind}");
    }
}

#[test]
fn build_rejects_invalid_configurations() {
    let cfg = ScenarioConfig {
        compression: 0.9,
        ..ScenarioConfig::default_for(ScenarioKind::Tumbling)
    };
    assert!(matches!(
        build(&cfg),
        Err(ScenarioError::InvalidCompression(_))
    ));
    let cfg = ScenarioConfig {
        frame_period_s: f64::NAN,
        ..ScenarioConfig::default_for(ScenarioKind::Ellipse)
    };
    assert!(matches!(
        build(&cfg),
        Err(ScenarioError::InvalidFramePeriod(_))
    ));
}

#[test]
fn a_range_scale_moves_every_leg_out_and_fits_a_large_target() {
    use crate::presets::{FLY_AROUND_RANGE_M, range_scale_to_fit};
    for kind in [ScenarioKind::SlowSpin, ScenarioKind::Tumbling] {
        let base = ScenarioConfig::default_for(kind);
        let near = build(&base).unwrap();
        let far = build(&ScenarioConfig {
            range_scale: 2.5,
            ..base.clone()
        })
        .unwrap();
        for t in [0.0, 400.0, 1000.0] {
            let (a, b) = (near.state_at(t), far.state_at(t));
            let ratio = b.t_sensor_target.translation.norm() / a.t_sensor_target.translation.norm();
            assert!((ratio - 2.5).abs() < 0.02, "{kind} at {t} s: {ratio}");
        }
        let bad = ScenarioConfig {
            range_scale: 0.5,
            ..base
        };
        assert!(build(&bad).is_err());
    }
    // deos (1.60 m) keeps the paper's legs; a 10 m radius fits at 38 m;
    // envisat's 21.1 m would fit at 80 m but stays within a 60 m gate.
    assert_eq!(range_scale_to_fit(1.6008, 38.4, 60.0), 1.0);
    let k = range_scale_to_fit(10.0, 38.4, 60.0);
    let half = (0.4 * 38.4f64).to_radians();
    assert!((10.0 / (k * FLY_AROUND_RANGE_M) - half.sin()).abs() < 1e-12);
    let k = range_scale_to_fit(21.1, 38.4, 60.0);
    assert!((k * FLY_AROUND_RANGE_M + 21.1 - 60.0).abs() < 1e-12);
}
