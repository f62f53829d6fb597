use super::*;
use crate::refinement::RefinementConfig;
use nalgebra::{Rotation3, Vector3};
use spacepose_model::Target;

/// Noise-free points of `target` at `t_sensor_target` on a grid of rays
/// (0.25° apart, ±12°) from a sensor at the origin looking along +z.
fn cast(target: &Target, t_sensor_target: &Pose) -> Vec<Point> {
    let inv = t_sensor_target.inverse();
    let step = 0.25f64.to_radians();
    let mut points = Vec::new();
    for i in -48..=48 {
        for j in -48..=48 {
            let d = Vector3::new(
                (f64::from(i) * step).tan(),
                (f64::from(j) * step).tan(),
                1.0,
            )
            .normalize();
            if let Some(hit) = target.cast_ray(&inv.translation, &(inv.rotation * d), 50.0) {
                points.push(Point::from_vector(&(d * hit.distance), 1.0, 0.0));
            }
        }
    }
    points
}

/// Deos 6 m away, its tower end turned 50° toward the sensor.
fn tower_in_view() -> Pose {
    // Body x (tower) toward the sensor (−z), then tilted.
    let face_sensor = Rotation3::from_axis_angle(&Vector3::y_axis(), -std::f64::consts::FRAC_PI_2);
    let tilt = Rotation3::from_axis_angle(&Vector3::x_axis(), 40f64.to_radians());
    Pose::new(tilt * face_sensor, Vector3::new(0.2, -0.1, 6.0))
}

#[test]
fn a_flipped_estimate_is_replaced_by_its_twin() {
    let target = Target::builtin("deos").unwrap();
    let refiner = Refiner::new(&target, RefinementConfig::default()).unwrap();
    let truth = tower_in_view();
    let cloud = cast(&target, &truth);
    assert!(cloud.len() > 1000, "{}", cloud.len());
    // The tower-flip twin, refined: the body fits, the tower does not.
    let ry180 = target.twins()[1];
    let flipped = Pose::new(truth.rotation * ry180, truth.translation);
    let estimate = refiner.refine(&cloud, &flipped).unwrap();
    let before_deg = estimate.t_sensor_target.error_to(&truth).0.to_degrees();
    assert!(before_deg > 170.0, "the flip refined to {before_deg}°");
    assert!(
        refiner.accepts(estimate.f_conv_m2),
        "f_CONV {}",
        estimate.f_conv_m2
    );

    let (checked, outcome) = check_twins(&refiner, &cloud, estimate, &TwinCheckConfig::default());
    let (after_rad, after_m) = checked.t_sensor_target.error_to(&truth);
    let after_deg = after_rad.to_degrees();
    assert_eq!(outcome.twin, Some(1), "{outcome:?}");
    assert!(
        after_deg < 0.5 && after_m < 0.01,
        "{after_deg}° {after_m} m"
    );
    assert!(outcome.best_twin_explained.unwrap() > outcome.explained);
}

#[test]
fn a_correct_estimate_is_kept_and_the_check_can_be_disabled() {
    let target = Target::builtin("deos").unwrap();
    let refiner = Refiner::new(&target, RefinementConfig::default()).unwrap();
    let truth = tower_in_view();
    let cloud = cast(&target, &truth);
    let estimate = refiner.refine(&cloud, &truth).unwrap();
    let (checked, outcome) = check_twins(
        &refiner,
        &cloud,
        estimate.clone(),
        &TwinCheckConfig::default(),
    );
    assert_eq!(outcome.twin, None, "{outcome:?}");
    assert_eq!(checked.t_sensor_target, estimate.t_sensor_target);
    assert!(outcome.explained > 0.99, "{outcome:?}");
    assert!(outcome.best_twin_explained.unwrap() < outcome.explained);

    let flipped = Pose::new(truth.rotation * target.twins()[1], truth.translation);
    let estimate = refiner.refine(&cloud, &flipped).unwrap();
    let off = TwinCheckConfig {
        enabled: false,
        ..TwinCheckConfig::default()
    };
    let (checked, outcome) = check_twins(&refiner, &cloud, estimate.clone(), &off);
    assert_eq!(outcome.twin, None);
    assert_eq!(outcome.best_twin_explained, None);
    assert_eq!(checked.t_sensor_target, estimate.t_sensor_target);
}
