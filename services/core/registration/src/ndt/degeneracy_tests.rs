//! Degeneracy handling (`NdtParams::min_lever_arm_m`) on a plane with a
//! cylinder standing on it, seen end-on: the roll about the cylinder's axis
//! is unobservable, everything else is.

use super::*;
use crate::normal_equations::Constrained;
use crate::params::NdtMapParams;
use nalgebra::{Rotation3, Vector6};

/// A disc of radius 0.7 m in the plane x = 0 and a cylinder of radius
/// 0.12 m along +x up to 0.45 m, sampled every `s` metres (body frame).
pub(crate) fn plane_and_cylinder(s: f64) -> Vec<Vector3<f64>> {
    let mut pts = Vec::new();
    let n = (0.7 / s) as i32;
    for i in -n..=n {
        for j in -n..=n {
            let (y, z) = (f64::from(i) * s, f64::from(j) * s);
            if y * y + z * z <= 0.49 && y * y + z * z >= 0.0144 {
                pts.push(Vector3::new(0.0, y, z));
            }
        }
    }
    let around = (2.0 * std::f64::consts::PI * 0.12 / s) as i32;
    for k in 0..around {
        let a = f64::from(k) / f64::from(around) * 2.0 * std::f64::consts::PI;
        for h in 1..=(0.45 / s) as i32 {
            pts.push(Vector3::new(
                f64::from(h) * s,
                0.12 * a.cos(),
                0.12 * a.sin(),
            ));
        }
    }
    pts
}

/// The sensor 2 m in front of the plane, looking along −x of the body.
pub(crate) fn truth() -> Pose {
    let look = Rotation3::from_axis_angle(&Vector3::y_axis(), std::f64::consts::FRAC_PI_2);
    Pose::new(look, Vector3::new(0.0, 0.0, 2.0))
}

pub(crate) fn cloud(model: &[Vector3<f64>], t_sensor_target: &Pose) -> Vec<Point> {
    model
        .iter()
        .map(|p| Point::from_vector(&t_sensor_target.transform(p), 1.0, 0.0))
        .collect()
}

pub(crate) fn map(model: &[Vector3<f64>]) -> NdtMap {
    NdtMap::build(model, &NdtMapParams::default()).unwrap()
}

#[test]
fn the_roll_about_the_cylinder_is_the_one_unconstrained_rotation() {
    let model = plane_and_cylinder(0.01);
    let map = map(&model);
    let t_target_sensor = truth().inverse();
    let sensor_points: Vec<Vector3<f64>> = cloud(&model, &truth())
        .iter()
        .map(Point::position)
        .collect();
    let params = NdtParams::default();
    let (h, n) = geometric_information(&map, &sensor_points, &t_target_sensor, 1, &params);
    assert!(n > 1000, "{n}");
    let c = Constrained::of(&h, n, 0.035, 0.0).unwrap();
    assert_eq!(c.dropped(), 1, "{c:?}");
    assert!(c.weakest_lever_arm_m < 0.01, "{}", c.weakest_lever_arm_m);
    // The kept rotations are orthogonal to the body x axis (the roll).
    for v in &c.basis {
        let rot = Vector3::new(v[0], v[1], v[2]);
        assert!(rot.dot(&Vector3::x()).abs() < 1e-3, "{v:?}");
    }
    // Nothing is dropped below a 1 mm lever arm.
    assert_eq!(Constrained::of(&h, n, 0.001, 0.0).unwrap().dropped(), 0);
    // A non-finite matrix or no point: no basis.
    assert!(Constrained::of(&(h * f64::NAN), n, 0.035, 0.0).is_none());
    assert!(Constrained::of(&h, 0, 0.035, 0.0).is_none());
    // Just above the weakest translation's cosine, that shift is left out
    // too, and the kept translations are orthogonal to it.
    let cosine = c.weakest_translation_cosine;
    let both = Constrained::of(&h, n, 0.035, cosine * 1.01).unwrap();
    // The cylinder's two radial shifts are alike: both may fall below.
    let kept: Vec<Vector3<f64>> = c
        .basis
        .iter()
        .take(2)
        .map(|v| Vector3::new(v[0], v[1], v[2]))
        .collect();
    let weak = crate::weak_directions::translations(&h, n, &kept);
    let k = weak
        .iter()
        .filter(|d| d.per_point.sqrt() < cosine * 1.01)
        .count();
    assert!(k >= 1);
    assert_eq!(
        (both.dropped(), both.held_translations(), both.basis.len()),
        (1, k, 5 - k)
    );
    for held in crate::weak_directions::Held::of(&h, 1, k).translations {
        for v in &both.basis {
            assert!(
                held.dot(&Vector3::new(v[3], v[4], v[5])).abs() < 1e-9,
                "{v:?}"
            );
        }
    }
    assert_eq!(
        Constrained::of(&h, n, 0.035, cosine * 0.99)
            .unwrap()
            .held_translations(),
        0
    );
}

#[test]
fn a_held_rotation_keeps_the_guess_and_the_rest_converges() {
    let model = plane_and_cylinder(0.01);
    let map = map(&model);
    let source = cloud(&model, &truth());
    // Guess: 3° of roll about the body x axis, 1.5° of tilt, 2 cm off.
    let t_target_sensor = truth().inverse();
    let offset = Vector6::new(
        3f64.to_radians(),
        1.5f64.to_radians(),
        0.0,
        0.0,
        0.01,
        0.015,
    );
    let guess = t_target_sensor.oplus(&offset);
    let params = NdtParams {
        min_lever_arm_m: 0.035,
        termination_rotation_deg: 0.005,
        termination_translation_m: 5e-5,
        max_iterations: 60,
        ..NdtParams::default()
    };
    let r = register_ndt(&map, &source, &guess, &params).unwrap();
    assert_eq!(r.degenerate_directions, 1);
    assert!(r.weakest_lever_arm_m < 0.01);
    // The roll is still the guess's; the tilt and the offset are gone.
    let err = r.t_target_sensor.ominus(&t_target_sensor);
    let roll_deg = err[0].to_degrees();
    assert!((roll_deg - 3.0).abs() < 0.05, "roll {roll_deg}°");
    let tilt_deg = Vector3::new(0.0, err[1], err[2]).norm().to_degrees();
    assert!(tilt_deg < 0.05, "tilt {tilt_deg}°");
    let off_m = err.fixed_rows::<3>(3).norm();
    assert!(off_m < 0.002, "offset {off_m} m");
    // Off (the paper), the reported figures say so.
    let plain = register_ndt(&map, &source, &guess, &NdtParams::default()).unwrap();
    assert_eq!(plain.degenerate_directions, 0);
    assert!(plain.weakest_lever_arm_m.is_nan());
}
