use super::*;

fn pred() -> TargetPrediction {
    TargetPrediction {
        t_s: 10.0,
        p_sensor_target: Vector3::new(0.0, 0.0, 10.0),
        v_sensor: Vector3::new(0.0, 0.0, -0.5),
        attitude: None,
    }
}

#[test]
fn the_sphere_follows_the_propagated_centre() {
    let c = IngestConfig::default();
    let (roi, issue) = Roi::for_frame(&c, Some(&pred()), 11.0, 12.0);
    assert_eq!(issue, None);
    assert_eq!(roi.kind(), RoiKind::Predicted);
    // Propagated to the scan end: 10 - 0.5 * 2 = 9 m.
    assert!((roi.centre().unwrap() - Vector3::new(0.0, 0.0, 9.0)).norm() < 1e-12);
    let r = c.target_bounding_radius_m + c.margin_m + 0.5;
    let at = |z: f64| Point::new(0.0, 0.0, z as f32, 1.0, 11.5);
    assert!(roi.contains(&at(9.0 + r - 0.01)));
    assert!(!roi.contains(&at(9.0 + r + 0.01)));
    assert!(!roi.contains(&at(9.0 - r - 0.01)));
    assert!(!roi.contains(&Point::new(f32::NAN, 0.0, 9.0, 1.0, 11.5)));
}

#[test]
fn stale_or_non_finite_predictions_fall_back_to_the_range_gate() {
    let c = IngestConfig::default();
    let (roi, issue) = Roi::for_frame(&c, Some(&pred()), 30.0, 31.0);
    assert_eq!(issue, Some(PredictionIssue::Stale));
    assert_eq!(roi.kind(), RoiKind::RangeOnly);
    let mut p = pred();
    p.v_sensor.x = f64::NAN;
    let (roi, issue) = Roi::for_frame(&c, Some(&p), 10.0, 11.0);
    assert_eq!(issue, Some(PredictionIssue::NonFinite));
    assert!(roi.contains(&Point::new(20.0, 0.0, 30.0, 1.0, 11.0)));
    assert!(!roi.contains(&Point::new(0.0, 0.0, 0.2, 1.0, 11.0)));
    assert!(!roi.contains(&Point::new(0.0, 0.0, 70.0, 1.0, 11.0)));
}

#[test]
fn with_an_attitude_the_body_box_follows_the_rotating_target() {
    let c = IngestConfig {
        margin_m: 0.1,
        body_box: Some(AxisBox {
            min_m: [-1.5, -0.5, -0.5],
            max_m: [1.5, 0.5, 0.5],
        }),
        ..IngestConfig::default()
    };
    // Long axis along sensor x at t = 0, turning at 90°/s about body z.
    let p = TargetPrediction {
        t_s: 0.0,
        p_sensor_target: Vector3::new(0.0, 0.0, 10.0),
        v_sensor: Vector3::zeros(),
        attitude: Some(AttitudePrediction {
            r_sensor_target: Rotation3::identity(),
            w_target: Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2),
            sigma_rot_rad: 0.0,
            sigma_w_radps: 0.0,
        }),
    };
    let (roi, _) = Roi::for_frame(&c, Some(&p), 0.0, 1.0);
    assert_eq!(roi.kind(), RoiKind::PredictedWithAttitude);
    // At the scan start the long axis is along x, at the end along y.
    assert!(roi.contains(&Point::new(1.4, 0.0, 10.0, 1.0, 0.0)));
    assert!(!roi.contains(&Point::new(0.0, 1.4, 10.0, 1.0, 0.0)));
    assert!(roi.contains(&Point::new(0.0, 1.4, 10.0, 1.0, 1.0)));
    assert!(!roi.contains(&Point::new(1.4, 0.0, 10.0, 1.0, 1.0)));
    // A point below the target (an arm) is inside the sphere, not the box.
    assert!(!roi.contains(&Point::new(0.0, 0.9, 10.0, 1.0, 0.0)));
    // An attitude too uncertain for the margin (3 × 2° × 1.6 m > 0.1 m
    // after 1 s): the sphere alone, so a wrong box cannot cut the target.
    let unsure = TargetPrediction {
        attitude: p.attitude.map(|a| AttitudePrediction {
            sigma_w_radps: 2f64.to_radians(),
            ..a
        }),
        ..p
    };
    let (roi, _) = Roi::for_frame(&c, Some(&unsure), 0.0, 1.0);
    assert_eq!(roi.kind(), RoiKind::Predicted);
    // Without an attitude, the sphere alone.
    let (roi, _) = Roi::for_frame(
        &c,
        Some(&TargetPrediction {
            attitude: None,
            ..p
        }),
        0.0,
        1.0,
    );
    assert_eq!(roi.kind(), RoiKind::Predicted);
    assert!(roi.contains(&Point::new(0.0, 0.9, 10.0, 1.0, 0.0)));
}

#[test]
fn the_static_box_applies_only_without_a_prediction() {
    let c = IngestConfig {
        static_box: Some(AxisBox {
            min_m: [-2.0, -2.0, 5.0],
            max_m: [2.0, 2.0, 15.0],
        }),
        ..IngestConfig::default()
    };
    let (roi, _) = Roi::for_frame(&c, None, 0.0, 1.0);
    assert_eq!(roi.kind(), RoiKind::StaticBox);
    assert!(roi.contains(&Point::new(1.0, 1.0, 10.0, 1.0, 0.5)));
    assert!(!roi.contains(&Point::new(3.0, 1.0, 10.0, 1.0, 0.5)));
    let (roi, _) = Roi::for_frame(&c, Some(&pred()), 10.0, 11.0);
    assert_eq!(roi.kind(), RoiKind::Predicted);
}
