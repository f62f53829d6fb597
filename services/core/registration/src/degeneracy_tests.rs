//! [`hold_weak_rotations`] on the plane-and-cylinder scene seen end-on,
//! whose roll about the cylinder (body x) is unobservable.

use super::*;
use crate::ndt::degeneracy_tests::{cloud, map, plane_and_cylinder, truth};
use crate::register_ndt;
use spacepose_geometry::so3;

/// The true pose, and a result turned from it by `roll_deg` about body x,
/// `pitch_deg` about body y and moved by `dx_m` along x.
fn turned(initial: &Pose, roll_deg: f64, pitch_deg: f64, dx_m: f64) -> Pose {
    let (r, p) = (roll_deg.to_radians(), pitch_deg.to_radians());
    initial.oplus(&Vector6::new(r, p, 0.0, dx_m, 0.0, 0.0))
}

#[test]
fn the_unobservable_roll_is_held_at_the_initial_pose_and_the_rest_kept() {
    let model = plane_and_cylinder(0.01);
    let map = map(&model);
    let source = cloud(&model, &truth());
    let initial = truth().inverse();
    let params = NdtParams {
        min_lever_arm_m: 0.035,
        ..NdtParams::default()
    };
    // A result as ICP could give it: rolled 5° (nothing pulls it back),
    // pitched 1° and moved 2 cm along the cylinder.
    let mut result = register_ndt(&map, &source, &initial, &params).unwrap();
    assert_eq!(result.degenerate_directions, 1);
    result.t_target_sensor = turned(&initial, 5.0, 1.0, 0.02);
    result.degenerate_directions = 0;
    result.geometric_information = None;
    let held = hold_weak_rotations(&map, &source, &initial, result.clone(), &params);
    assert_eq!(held.degenerate_directions, 1);
    assert!(
        held.weakest_lever_arm_m < 0.01,
        "{}",
        held.weakest_lever_arm_m
    );
    assert!(held.geometric_information.is_some());
    let eps = held.t_target_sensor.ominus(&initial);
    let roll_deg = eps[0].to_degrees();
    let pitch_deg = eps[1].to_degrees();
    assert!(roll_deg.abs() < 1e-3, "roll {roll_deg}");
    assert!((pitch_deg - 1.0).abs() < 0.01, "pitch {pitch_deg}");
    // The roll axis passes through the body origin: no translation goes
    // with it, and the 2 cm stay.
    assert!((eps[3] - 0.02).abs() < 1e-3, "{eps:?}");
    // Figures other than the pose and the degeneracy are the result's own.
    assert_eq!(held.iterations, result.iterations);
    assert_eq!(held.cost, result.cost);
    assert_eq!(held.information, result.information);
}

#[test]
fn nothing_is_held_where_every_rotation_is_constrained_or_when_disabled() {
    let model = plane_and_cylinder(0.01);
    let map = map(&model);
    let source = cloud(&model, &truth());
    let initial = truth().inverse();
    let result = register_ndt(
        &map,
        &source,
        &initial,
        &NdtParams {
            min_lever_arm_m: 0.035,
            ..NdtParams::default()
        },
    )
    .unwrap();
    let mut rolled = result.clone();
    rolled.t_target_sensor = turned(&initial, 5.0, 1.0, 0.0);
    // A 1 mm threshold: the roll counts as constrained, the pose stays.
    let loose = NdtParams {
        min_lever_arm_m: 0.001,
        ..NdtParams::default()
    };
    let kept = hold_weak_rotations(&map, &source, &initial, rolled.clone(), &loose);
    assert_eq!(kept.degenerate_directions, 0);
    assert!(kept.weakest_lever_arm_m.is_finite());
    let turn = so3::distance(
        &kept.t_target_sensor.rotation,
        &rolled.t_target_sensor.rotation,
    );
    assert!(turn < 1e-12, "{turn}");
    // Disabled: returned as given.
    let off = NdtParams {
        min_lever_arm_m: 0.0,
        ..NdtParams::default()
    };
    assert_eq!(
        hold_weak_rotations(&map, &source, &initial, rolled.clone(), &off),
        rolled
    );
}
