//! [`hold_weak_directions`] on the plane-and-cylinder scene seen end-on,
//! whose roll about the cylinder (body x) is unobservable.

use super::*;
use crate::ndt::degeneracy_tests::{cloud, map, plane_and_cylinder, truth};
use crate::register_ndt;
use nalgebra::Vector6;
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
    let held = hold_weak_directions(&map, &source, &initial, result.clone(), &params);
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
    let kept = hold_weak_directions(&map, &source, &initial, rolled.clone(), &loose);
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
        hold_weak_directions(&map, &source, &initial, rolled.clone(), &off),
        rolled
    );
}

#[test]
fn a_weak_translation_is_held_at_the_initial_pose_with_the_turn_that_goes_with_it() {
    let model = plane_and_cylinder(0.01);
    let map = map(&model);
    let source = cloud(&model, &truth());
    let initial = truth().inverse();
    let probe = NdtParams {
        min_lever_arm_m: 0.035,
        ..NdtParams::default()
    };
    let result = register_ndt(&map, &source, &initial, &probe).unwrap();
    let cosine = result.weakest_translation_cosine;
    assert!(cosine > 0.0 && cosine < 1.0, "{cosine}");
    // A threshold just above this view's weakest cosine holds that shift.
    let params = NdtParams {
        min_translation_cosine: (cosine * 1.01).min(0.999),
        ..probe
    };
    let mut moved = result.clone();
    moved.t_target_sensor =
        turned(&initial, 0.0, 1.0, 0.0).oplus(&Vector6::new(0.0, 0.0, 0.0, 0.03, -0.04, 0.05));
    let held = hold_weak_directions(&map, &source, &initial, moved.clone(), &params);
    let k = held.held_translations;
    assert!(
        held.degenerate_directions == 1 && (1..3).contains(&k),
        "{k}"
    );
    let h = held.geometric_information.expect("computed");
    let axes = crate::weak_directions::Held::of(&h, 1, k);
    let eps = held.t_target_sensor.ominus(&initial);
    // No shift along the held translations, no turn about the held roll.
    for axis in &axes.translations {
        let shift = axis.dot(&eps.fixed_rows::<3>(3));
        assert!(shift.abs() < 1e-6, "{shift} {eps:?}");
    }
    assert!(axes.rotations[0].dot(&eps.fixed_rows::<3>(0)).abs() < 1e-6);
    // The 3-5 cm the result had were moved, not ignored.
    let before = moved.t_target_sensor.ominus(&initial);
    let residual = (eps - before).fixed_rows::<3>(3).into_owned();
    assert!(residual.norm() > 1e-3, "nothing was held: {residual:?}");
    // Off: nothing held.
    let none = hold_weak_directions(&map, &source, &initial, moved, &probe);
    assert_eq!(none.held_translations, 0);
}
