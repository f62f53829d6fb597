use super::*;
use spacepose_scenario::{ScenarioConfig, ScenarioKind, build};

fn tumbling() -> Box<dyn Scenario> {
    build(&ScenarioConfig::default_for(ScenarioKind::Tumbling)).unwrap()
}

fn still() -> Mismatch {
    Mismatch {
        jitter_deg: 0.0,
        acceleration_mps2: 0.0,
        ..Mismatch::default()
    }
}

/// Without jitter or acceleration the path is the scenario's own motion
/// (within the interpolation's error), and departs from the constant
/// velocities of the scan-end truth.
#[test]
fn the_path_is_the_scenarios_motion() {
    let s = tumbling();
    let (path, truth) = still().scan_path(s.as_ref(), (9.0, 10.0), 7, 9);
    assert!(truth.t_sensor_target.error_to(&s.pose_at(10.0)).0 < 1e-12);
    let mut worst_cv: f64 = 0.0;
    for k in 0..=20 {
        let t = 9.0 + k as f64 * 0.05;
        let exact = s.pose_at(t);
        let sampled = Pose::new(path.rotation(t), path.position(t));
        let (ang, pos) = sampled.error_to(&exact);
        assert!(
            ang.to_degrees() < 1e-3 && pos < 1e-5,
            "t {t}: {ang} rad {pos} m"
        );
        let cv = truth.extrapolate(t - 10.0);
        worst_cv = worst_cv.max(cv.error_to(&exact).0.to_degrees());
    }
    // The torque-free tumble is not a constant rate over a second.
    assert!(worst_cv > 0.01, "{worst_cv}");
}

/// The jitter turns the pose by about its amplitude, is continuous in time
/// and the same for one seed; the acceleration vanishes at the scan end.
#[test]
fn jitter_and_acceleration_move_the_pose_as_configured() {
    let s = tumbling();
    let m = Mismatch {
        acceleration_mps2: 0.0,
        ..Mismatch::default()
    };
    let (path, truth) = m.scan_path(s.as_ref(), (9.0, 10.0), 7, 9);
    let (ang, _) = truth.t_sensor_target.error_to(&s.pose_at(10.0));
    assert!(ang.to_degrees() < 4.0 * 0.02 * 2.0, "{}", ang.to_degrees());
    let j = m.jitter(7);
    assert!(j.at(3.0).angle() < 1e-3 * 6.0);
    // At most 6 sines × 2π 5 Hz × 0.02° over 1 ms: under 1e-4 rad.
    assert!((j.at(3.0).inverse() * j.at(3.001)).angle() < 1e-4);
    assert_eq!(m.jitter(7).at(1.5), j.at(1.5));
    let _ = path;
    let pushed = Mismatch {
        jitter_deg: 0.0,
        acceleration_mps2: 0.1,
        ..Mismatch::default()
    };
    let (path, truth) = pushed.scan_path(s.as_ref(), (9.0, 10.0), 7, 9);
    assert!(truth.t_sensor_target.error_to(&s.pose_at(10.0)).1 < 1e-12);
    let off = (path.position(9.0) - s.pose_at(9.0).translation).norm();
    assert!((off - 0.05).abs() < 1e-6, "½ a t² = 5 cm, got {off}");
}

#[test]
fn bad_settings_are_refused() {
    for bad in [
        Mismatch {
            jitter_deg: f64::NAN,
            ..Mismatch::default()
        },
        Mismatch {
            jitter_hz: [3.0, 1.0],
            ..Mismatch::default()
        },
        Mismatch {
            acceleration_mps2: -1.0,
            ..Mismatch::default()
        },
    ] {
        let e = bad.validate();
        assert!(
            matches!(&e, Err(SimError::InvalidConfig { field, .. }) if field.starts_with("mismatch.")),
            "{e:?}"
        );
    }
    assert!(Mismatch::default().validate().is_ok());
}
