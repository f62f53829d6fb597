use super::*;
use nalgebra::Matrix6;
use spacepose_registration::{Cost, Increment};

/// A registration at `t_ts` that held `held` rotations, with geometric
/// information `h`.
fn registration(t_ts: Pose, held: usize, h: Matrix6<f64>) -> Registration {
    Registration {
        t_target_sensor: t_ts,
        converged: true,
        iterations: 5,
        cost: Cost {
            total: 1.0,
            mean: 0.01,
        },
        inliers: 500,
        valid_points: 500,
        skipped_non_finite: 0,
        mean_squared_distance_m2: 1e-4,
        f_conv_m2: None,
        information: h,
        last_increment: Increment::default(),
        degenerate_directions: held,
        weakest_lever_arm_m: 0.01,
        held_translations: 0,
        weakest_translation_cosine: 0.5,
        geometric_information: Some(h),
    }
}

/// A registration at `t_ts` that held one translation, with geometric
/// information `h`.
fn shifted(t_ts: Pose, h: Matrix6<f64>) -> Registration {
    Registration {
        held_translations: 1,
        weakest_translation_cosine: 0.01,
        ..registration(t_ts, 0, h)
    }
}

/// Information that hardly constrains the shift along the target's x.
fn weak_x_shift() -> Matrix6<f64> {
    let mut h = Matrix6::identity() * 1e6;
    h[(3, 3)] = 1e-3;
    h
}

/// Variance of the position along `axis_sensor` in a `t_sensor_target`
/// covariance.
fn variance_along(cov: &Matrix6<f64>, axis_sensor: &Vector3<f64>) -> f64 {
    let p = cov.fixed_view::<3, 3>(3, 3).into_owned();
    (axis_sensor.transpose() * p * axis_sensor)[(0, 0)]
}

/// A prediction at `pose` with attitude variance `var_rad2` on every axis.
fn prediction(pose: Pose, var_rad2: f64) -> Prediction {
    let mut covariance = Matrix6::identity() * 1e-4;
    covariance
        .fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(nalgebra::Matrix3::identity() * var_rad2));
    Prediction {
        t: 1.0,
        pose,
        v_sensor: Vector3::zeros(),
        w_target: Vector3::zeros(),
        w_inertial_sensor: nalgebra::Vector3::zeros(),
        covariance,
        attitude_covariance: spacepose_filter::Matrix9::identity(),
        position_covariance: Matrix6::identity(),
    }
}

/// Information that hardly constrains the rotation about the target's z
/// (a lever arm of millimetres), and the rest well.
fn weak_z() -> Matrix6<f64> {
    let mut h = Matrix6::identity() * 1e6;
    h[(2, 2)] = 10.0;
    h
}

/// A pose whose rotation moves the target's z onto the sensor's x.
fn turned_pose() -> Pose {
    Pose::new(
        so3::exp(&Vector3::new(0.0, std::f64::consts::FRAC_PI_2, 0.0)),
        Vector3::new(0.2, -0.1, 12.0),
    )
}

/// Variance of the attitude about `axis_sensor` in a `t_sensor_target`
/// covariance.
fn variance_about(cov: &Matrix6<f64>, axis_sensor: &Vector3<f64>) -> f64 {
    let p = cov.fixed_view::<3, 3>(0, 0).into_owned();
    (axis_sensor.transpose() * p * axis_sensor)[(0, 0)]
}

#[test]
fn nothing_held_is_none() {
    let r = registration(Pose::identity(), 0, weak_z());
    assert!(HeldAxes::of(&r, None, &prediction(Pose::identity(), 1e-4)).is_none());
}

#[test]
fn a_hold_at_the_prediction_is_as_uncertain_as_the_prediction() {
    let t_ts = turned_pose();
    let var = 3f64.to_radians().powi(2);
    let p = prediction(t_ts.inverse(), var);
    let held = HeldAxes::of(&registration(t_ts, 1, weak_z()), None, &p).unwrap();
    assert_eq!(held.count, 1);
    assert!(
        (held.sigma_rad - var.sqrt()).abs() < 1e-12,
        "{}",
        held.sigma_rad
    );
    // The target's z, the held axis, in the sensor frame.
    let axis_sensor = t_ts.rotation.inverse() * Vector3::z();
    let base = Matrix6::identity() * 1e-6;
    let (fused, published) = held.covariances(&t_ts, &base);
    let added = variance_about(&published, &axis_sensor) - 1e-6;
    assert!(
        (added - var).abs() < 1e-12 * var.max(1.0),
        "{added} vs {var}"
    );
    // The other rotations are as they were.
    let other = t_ts.rotation.inverse() * Vector3::x();
    assert!((variance_about(&published, &other) - 1e-6).abs() < 1e-15);
    // What the filter fuses says nothing about the held angle.
    assert!(variance_about(&fused, &axis_sensor) >= 1.0);
}

#[test]
fn a_hold_away_from_the_prediction_adds_the_turn() {
    let t_ts = turned_pose();
    let var = 1e-6;
    // The prediction 4° away about the held axis (the target's z).
    let turned = Pose::new(
        so3::exp(&Vector3::new(0.0, 0.0, 4f64.to_radians())),
        Vector3::zeros(),
    );
    let p = prediction(turned.compose(&t_ts).inverse(), var);
    let held = HeldAxes::of(&registration(t_ts, 1, weak_z()), None, &p).unwrap();
    let expected = (var + 4f64.to_radians().powi(2)).sqrt();
    assert!(
        (held.sigma_rad - expected).abs() < 1e-9,
        "{} vs {expected}",
        held.sigma_rad
    );
}

#[test]
fn a_hold_on_the_fitted_line_carries_the_line_uncertainty() {
    let t_ts = turned_pose();
    let line_sigma_rad = 0.2f64.to_radians();
    let p = prediction(t_ts.inverse(), 0.5);
    let held = HeldAxes::of(&registration(t_ts, 1, weak_z()), Some(line_sigma_rad), &p).unwrap();
    assert_eq!(held.sigma_rad, line_sigma_rad);
    // The line is independent of the filter: it is fused with its own σ.
    let axis_sensor = t_ts.rotation.inverse() * Vector3::z();
    let (fused, published) = held.covariances(&t_ts, &Matrix6::zeros());
    assert_eq!(fused, published);
    let v = variance_about(&fused, &axis_sensor);
    assert!((v - line_sigma_rad.powi(2)).abs() < 1e-12, "{v}");
}

#[test]
fn the_held_doubt_follows_the_limit() {
    let l = crate::LossConfig::default();
    let mut held = HeldAxes::of(
        &registration(turned_pose(), 1, weak_z()),
        None,
        &prediction(turned_pose().inverse(), 0.0),
    )
    .unwrap();
    assert!(crate::assess::held_doubt(&l, Some(&held)).is_none());
    held.sigma_rad = (l.max_held_sigma_deg * 1.01).to_radians();
    let reason = crate::assess::held_doubt(&l, Some(&held)).unwrap();
    assert!(reason.contains("held"), "{reason}");
    assert!(crate::assess::held_doubt(&l, None).is_none());
}

#[test]
fn a_held_shift_at_the_prediction_is_as_uncertain_as_the_prediction() {
    let t_ts = turned_pose();
    // Attitude exactly known, position σ 1 cm.
    let p = prediction(t_ts.inverse(), 0.0);
    let held = HeldAxes::of(&shifted(t_ts, weak_x_shift()), None, &p).unwrap();
    assert_eq!((held.count, held.translations), (0, 1));
    assert!((held.sigma_m - 0.01).abs() < 1e-9, "{}", held.sigma_m);
    assert_eq!(held.sigma_rad, 0.0);
    let along = t_ts.rotation.inverse() * Vector3::x();
    let base = Matrix6::identity() * 1e-6;
    let (fused, published) = held.covariances(&t_ts, &base);
    let added = variance_along(&published, &along) - 1e-6;
    assert!((added - 1e-4).abs() < 1e-12, "{added}");
    let across = t_ts.rotation.inverse() * Vector3::y();
    assert!((variance_along(&published, &across) - 1e-6).abs() < 1e-15);
    assert!(variance_along(&fused, &along) >= 1.0);
}

#[test]
fn a_held_shift_away_from_the_prediction_adds_the_shift() {
    let t_ts = turned_pose();
    let predicted = Pose::new(t_ts.rotation, t_ts.translation - Vector3::x() * 0.3);
    let p = prediction(predicted.inverse(), 0.0);
    let held = HeldAxes::of(&shifted(t_ts, weak_x_shift()), None, &p).unwrap();
    let expected = (1e-4f64 + 0.09).sqrt();
    assert!((held.sigma_m - expected).abs() < 1e-9, "{}", held.sigma_m);
}

#[test]
fn the_held_shift_doubt_is_an_angle_seen_from_the_sensor() {
    let l = crate::LossConfig::default();
    let t_ts = turned_pose();
    let mut held = HeldAxes::of(
        &shifted(t_ts, weak_x_shift()),
        None,
        &prediction(t_ts.inverse(), 0.0),
    )
    .unwrap();
    assert!(crate::assess::held_doubt(&l, Some(&held)).is_none());
    let limit_m = held.range_m * l.max_held_sigma_deg.to_radians().tan();
    held.sigma_m = limit_m * 1.01;
    let reason = crate::assess::held_doubt(&l, Some(&held)).unwrap();
    assert!(reason.contains("translation"), "{reason}");
    held.sigma_m = limit_m * 0.99;
    assert!(crate::assess::held_doubt(&l, Some(&held)).is_none());
}
