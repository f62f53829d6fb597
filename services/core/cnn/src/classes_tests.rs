use super::*;
use spacepose_geometry::so3::{distance, distance_sym};

#[test]
fn spiral_count_and_class_count_match_the_paper() {
    // Eq. (7): n_s = floor(4π / (20°)²) = 103; 18 rolls: M = 1854; m = M/3 = 618
    // (seed 004 §V.B: "m = 618").
    assert_eq!(spiral_count(20f64.to_radians()), 103);
    let deos = Target::builtin("deos").unwrap();
    let table = ClassTable::for_target(&deos, 20.0).unwrap();
    assert_eq!(table.full_count(), 1854);
    assert_eq!(table.len(), 618);
    let none = ClassTable::new(20.0, &[]).unwrap();
    assert_eq!(none.len(), 1854);
    assert_eq!(none.full_count(), 1854);
    let envisat = Target::builtin("envisat").unwrap();
    assert_eq!(ClassTable::for_target(&envisat, 20.0).unwrap().len(), 1854);
}

#[test]
fn spiral_points_cover_the_sphere_evenly() {
    let pts: Vec<Vector3<f64>> = spiral(103)
        .into_iter()
        .map(|(yaw, pitch)| euler_zyx(yaw, pitch, 0.0) * Vector3::x())
        .collect();
    // Every direction of a fine test set is within ~Δα of a spiral point.
    let mut worst = 0.0f64;
    for i in 0..40 {
        for j in 0..80 {
            let theta = PI * (i as f64 + 0.5) / 40.0;
            let phi = TAU * j as f64 / 80.0;
            let d = Vector3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            let nearest = pts
                .iter()
                .map(|p| p.dot(&d).clamp(-1.0, 1.0).acos())
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(nearest);
        }
    }
    assert!(
        worst.to_degrees() < 20.0,
        "covering radius {:.1}°",
        worst.to_degrees()
    );
}

#[test]
fn reduced_classes_represent_every_class_once() {
    let deos = Target::builtin("deos").unwrap();
    let sym = deos.symmetries();
    let full = ClassTable::new(20.0, &[]).unwrap();
    let reduced = ClassTable::for_target(&deos, 20.0).unwrap();
    // Every class of the full table has a symmetric equivalent in the reduced one...
    for r in full.rotations() {
        let d = reduced
            .rotations()
            .iter()
            .map(|q| distance_sym(r, q, sym))
            .fold(f64::INFINITY, f64::min);
        assert!(d < 1e-9);
    }
    // ...and no two reduced classes are symmetric copies of each other.
    for (i, a) in reduced.rotations().iter().enumerate().step_by(7) {
        for b in &reduced.rotations()[i + 1..] {
            assert!(distance_sym(a, b, sym) > 1e-6);
        }
    }
}

#[test]
fn a_non_x_symmetry_is_reduced_greedily() {
    // A half-turn about z: not a roll symmetry. The spiral is not invariant
    // under it, so greedy reduction (drop a class within Δα/2 of a kept one,
    // d_sym) removes fewer than half the classes: measured M/m = 1.41 at 30°.
    let group = [
        Rotation3::identity(),
        Rotation3::from_axis_angle(&Vector3::z_axis(), PI),
    ];
    let table = ClassTable::new(30.0, &group).unwrap();
    let full = ClassTable::new(30.0, &[]).unwrap();
    let ratio = full.len() as f64 / table.len() as f64;
    assert!((1.2..=2.0).contains(&ratio), "ratio {ratio}");
    // Still a cover: every full class is within Δα/2 (d_sym) of a kept one.
    for r in full.rotations() {
        let d = table
            .rotations()
            .iter()
            .map(|q| distance_sym(r, q, &group))
            .fold(f64::INFINITY, f64::min);
        assert!(d < 15f64.to_radians());
    }
}

#[test]
fn bad_parameters_are_errors() {
    assert!(ClassTable::new(0.0, &[]).is_err());
    assert!(ClassTable::new(f64::NAN, &[]).is_err());
    let not_identity = [Rotation3::from_axis_angle(&Vector3::x_axis(), 1.0)];
    assert!(matches!(
        ClassTable::new(20.0, &not_identity),
        Err(CnnError::Symmetry(_))
    ));
}

#[test]
fn quaternions_match_the_rotations() {
    let table = ClassTable::new(30.0, &[]).unwrap();
    for (r, q) in table.rotations().iter().zip(table.quaternions_wxyz()) {
        assert!(q[0] >= 0.0);
        let uq = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            f64::from(q[0]),
            f64::from(q[1]),
            f64::from(q[2]),
            f64::from(q[3]),
        ));
        assert!(distance(r, &uq.to_rotation_matrix()) < 1e-6);
    }
}
