use std::f64::consts::PI;

use nalgebra::{Rotation3, Unit, Vector3};

use super::*;

fn rot(axis: Vector3<f64>, angle: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Unit::new_normalize(axis), angle)
}

#[test]
fn angle_between_is_accurate_near_zero_and_pi() {
    let axis = Vector3::new(0.3, -0.5, 0.8);
    let a = rot(Vector3::new(1.0, 2.0, 0.5), 0.7);
    for angle in [1e-9, 1e-6, 0.3, 2.0, PI - 1e-7, PI] {
        let b = a * rot(axis, angle);
        let got = angle_between(&a, &b);
        assert!((got - angle).abs() < 1e-12, "{angle}: {got}");
    }
}

#[test]
fn rotation_axis_also_of_half_turns() {
    assert_eq!(rotation_axis(&Rotation3::identity()), Vector3::zeros());
    let u = Vector3::new(0.3, -0.5, 0.8).normalize();
    for angle in [1e-6, 0.5, 2.0, PI - 1e-9, PI] {
        let got = rotation_axis(&rot(u, angle));
        let err = if angle < PI - 1e-6 {
            (got - u).norm()
        } else {
            got.cross(&u).norm()
        };
        assert!(err < 1e-8, "{angle}: {got:?}");
    }
    let got = rotation_axis(&rot(u, -1.0));
    assert!((got + u).norm() < 1e-12);
}

#[test]
fn order_of_finds_the_smallest_order() {
    let x = Vector3::x();
    assert_eq!(order_of(&Rotation3::identity(), 12, 1e-6), Some(1));
    assert_eq!(order_of(&rot(x, PI), 12, 1e-6), Some(2));
    assert_eq!(order_of(&rot(x, -2.0 * PI / 3.0), 12, 1e-6), Some(3));
    assert_eq!(order_of(&rot(x, 4.0 * PI / 5.0), 12, 1e-6), Some(5));
    assert_eq!(order_of(&rot(x, PI / 6.0), 12, 1e-6), Some(12));
    assert_eq!(order_of(&rot(x, PI / 6.0), 11, 1e-6), None);
    assert_eq!(order_of(&rot(x, 1.0), 12, 1e-6), None);
}

#[test]
fn generate_closes_cyclic_and_dihedral_groups_and_refuses_infinite_ones() {
    let c3 = generate(&[rot(Vector3::x(), 2.0 * PI / 3.0)], 12, 1e-6, 60).expect("C3");
    assert_eq!(c3.len(), 3);
    assert!(c3[0].angle() < 1e-15);
    let d4 = generate(
        &[rot(Vector3::z(), PI / 2.0), rot(Vector3::x(), PI)],
        12,
        1e-6,
        60,
    )
    .expect("D4");
    assert_eq!(d4.len(), 8);
    // Every product stays in the set.
    for a in &d4 {
        for b in &d4 {
            assert!(position(&d4, &(a * b), 1e-9).is_some());
        }
    }
    // An irrational angle never closes; a 7-fold rotation has order > 6.
    assert!(generate(&[rot(Vector3::z(), 1.0)], 12, 1e-6, 60).is_none());
    assert!(generate(&[rot(Vector3::z(), 2.0 * PI / 7.0)], 6, 1e-6, 60).is_none());
    // The cap.
    assert!(generate(&[rot(Vector3::z(), PI / 6.0)], 12, 1e-6, 11).is_none());
}

#[test]
fn classes_of_twins() {
    let group = generate(&[rot(Vector3::x(), 2.0 * PI / 3.0)], 12, 1e-6, 60).expect("C3");
    let rx60 = rot(Vector3::x(), PI / 3.0);
    let rx180 = rot(Vector3::x(), PI);
    let ry180 = rot(Vector3::y(), PI);
    assert!(accounted_for(&group[1], &[], &group, 1e-6));
    assert!(!accounted_for(&rx60, &[], &group, 1e-6));
    assert!(accounted_for(&rx180, &[rx60], &group, 1e-6));
    assert!(!accounted_for(&ry180, &[rx60], &group, 1e-6));
    assert!(accounted_for(
        &rot(Vector3::x(), PI + 0.01),
        &[rx60],
        &group,
        0.02
    ));
    // Rx(180°)'s class {Rx(180°), Rx(300°), Rx(60°)} is listed as Rx(±60°).
    let rep = class_representative(&rx180, &group);
    assert!((angle_between(&Rotation3::identity(), &rep) - PI / 3.0).abs() < 1e-12);
}

#[test]
fn canonical_order_puts_the_identity_first_then_by_angle() {
    let x = Vector3::x();
    let group = generate(
        &[rot(x, 2.0 * PI / 3.0), rot(Vector3::y(), PI)],
        12,
        1e-6,
        60,
    )
    .expect("D3");
    let mut reversed = group.clone();
    reversed.reverse();
    let a = canonical_order(group, 1e-6);
    let b = canonical_order(reversed, 1e-6);
    assert_eq!(a.len(), 6);
    assert!(a[0].angle() < 1e-12);
    let angles: Vec<f64> = a.iter().map(Rotation3::angle).collect();
    assert!(angles.windows(2).all(|w| w[0] <= w[1] + 1e-6), "{angles:?}");
    for (p, q) in a.iter().zip(&b) {
        assert!(angle_between(p, q) < 1e-9);
    }
}
