//! Tests of motion compensation (kept beside `motion_compensation.rs`).

use super::*;
use crate::{FilterConfig, RelativeMotionFilter};
use nalgebra::{Rotation3, Unit};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spacepose_geometry::{Pose, so3};

struct Scene {
    body: Vec<Vector3<f64>>,
    times: Vec<f64>,
    r0: Rotation3<f64>,
    p0: Vector3<f64>,
    v: Vector3<f64>,
    w_target: Vector3<f64>,
}

const T_START: f64 = 4.0;
const T_END: f64 = 4.5;

impl Scene {
    fn new(n: usize) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(21);
        let body = (0..n)
            .map(|_| {
                Vector3::new(
                    rng.random_range(-2.0..2.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.5..1.5),
                )
            })
            .collect();
        let times = (0..n)
            .map(|i| T_START + (T_END - T_START) * i as f64 / (n - 1) as f64)
            .collect();
        Self {
            body,
            times,
            r0: so3::exp(&Vector3::new(-0.3, 0.5, 1.0)),
            p0: Vector3::new(0.5, -0.2, 15.0),
            v: Vector3::new(0.05, -0.03, -0.2),
            w_target: Unit::new_normalize(Vector3::new(-0.2, 0.7, 0.4)).into_inner()
                * 10f64.to_radians(),
        }
    }
    fn pose(&self, t: f64) -> Pose {
        Pose::new(
            self.r0 * so3::exp(&(self.w_target * t)),
            self.p0 + self.v * t,
        )
    }
    /// Each point where the sensor sees it at its own timestamp.
    fn blurred(&self) -> Vec<(Vector3<f64>, f64)> {
        self.body
            .iter()
            .zip(&self.times)
            .map(|(b, &t)| (self.pose(t).transform(b), t))
            .collect()
    }
    fn sharp(&self) -> Vec<Vector3<f64>> {
        let end = self.pose(T_END);
        self.body.iter().map(|b| end.transform(b)).collect()
    }
}

fn rms(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    (a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm_squared())
        .sum::<f64>()
        / a.len() as f64)
        .sqrt()
}

#[test]
fn compensation_with_true_motion_removes_the_blur() {
    let scene = Scene::new(5000);
    let end = scene.pose(T_END);
    let mc = MotionCompensation::new(
        T_END,
        end.translation,
        scene.v,
        end.rotation * scene.w_target,
    )
    .unwrap();
    let blurred = scene.blurred();
    let sharp = scene.sharp();
    let raw: Vec<_> = blurred.iter().map(|(z, _)| *z).collect();
    let fixed: Vec<_> = blurred
        .iter()
        .map(|(z, t)| mc.position_at_end(z, *t))
        .collect();
    let max_err = fixed
        .iter()
        .zip(&sharp)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    let (before, after) = (rms(&raw, &sharp), rms(&fixed, &sharp));
    println!(
        "motion compensation (f64, 0.5 s scan, 10 deg/s): RMS before {before:.4} m, after {after:.2e} m, max {max_err:.2e} m"
    );
    assert!(
        before > 0.05,
        "the scene must actually be blurred ({before})"
    );
    assert!(max_err < 1e-9, "max error {max_err}");

    // Same through `Point` (f32 coordinates) and the filter's own prediction.
    let mut f = RelativeMotionFilter::new(FilterConfig::default()).unwrap();
    f.initialize(T_START, &scene.pose(T_START), scene.v, scene.w_target)
        .unwrap();
    let mc_filter = MotionCompensation::from_prediction(&f.predict_at(T_END).unwrap()).unwrap();
    let points: Vec<Point> = blurred
        .iter()
        .map(|(z, t)| Point::from_vector(z, 0.5, *t))
        .collect();
    let out = mc_filter.compensate(&points).unwrap();
    let out_pos: Vec<_> = out.iter().map(|p| p.position()).collect();
    let in_pos: Vec<_> = points.iter().map(|p| p.position()).collect();
    let (before32, after32) = (rms(&in_pos, &sharp), rms(&out_pos, &sharp));
    println!("motion compensation (Point, f32): RMS before {before32:.4} m, after {after32:.2e} m");
    assert!(after32 < 5e-6, "f32 result {after32}");
    assert!(out.iter().all(|p| p.t == T_END && p.intensity == 0.5));
    let mut in_place = points.clone();
    mc_filter.compensate_in_place(&mut in_place).unwrap();
    assert_eq!(in_place, out);
}

#[test]
fn points_at_scan_end_do_not_move() {
    let mc = MotionCompensation::new(
        1.0,
        Vector3::new(0.0, 0.0, 10.0),
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(0.0, 0.3, 0.0),
    )
    .unwrap();
    let z = Vector3::new(1.0, 2.0, 9.0);
    assert!((mc.position_at_end(&z, 1.0) - z).norm() < 1e-15);
    // Pure translation: a point seen 0.5 s earlier moves by v Δt.
    let mc_t = MotionCompensation {
        w_sensor: Vector3::zeros(),
        ..mc
    };
    assert!((mc_t.position_at_end(&z, 0.5) - (z + Vector3::new(0.5, 0.0, 0.0))).norm() < 1e-15);
}

#[test]
fn non_finite_input_is_an_error() {
    let mc =
        MotionCompensation::new(1.0, Vector3::zeros(), Vector3::zeros(), Vector3::zeros()).unwrap();
    let mut pts = vec![
        Point::new(1.0, 2.0, 3.0, 1.0, 0.5),
        Point::new(1.0, f32::NAN, 3.0, 1.0, 0.5),
    ];
    assert_eq!(
        mc.compensate(&pts),
        Err(FilterError::NonFinitePoint { index: 1 })
    );
    let copy = pts.clone();
    assert!(mc.compensate_in_place(&mut pts).is_err());
    assert_eq!(pts[0], copy[0], "the slice must be untouched on error"); // NaN != NaN for the other
    assert!(
        MotionCompensation::new(
            f64::NAN,
            Vector3::zeros(),
            Vector3::zeros(),
            Vector3::zeros()
        )
        .is_err()
    );
    assert_eq!(mc.compensate(&[]).unwrap(), vec![]);
}

/// The one-`sin_cos` fixed-axis rotation equals Eq. (12) written with a
/// full `so3::exp`, for rates from zero to fast tumbles and both signs of
/// `Δt`.
#[test]
fn fixed_axis_rotation_matches_the_full_exponential() {
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    let unit = |rng: &mut ChaCha8Rng| {
        Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
    };
    for rate in [0.0, 1e-9, 0.02, 0.17, 1.0, 5.0] {
        let w = unit(&mut rng).normalize() * rate;
        let mc = MotionCompensation::new(10.0, unit(&mut rng) * 10.0, unit(&mut rng), w).unwrap();
        for _ in 0..200 {
            let z = unit(&mut rng) * 12.0;
            let t = 10.0 + rng.random_range(-1.5..0.5);
            let dt = mc.t_end - t;
            let reference =
                mc.p_sensor + so3::exp(&(mc.w_sensor * dt)) * (z - mc.p_sensor + mc.v_sensor * dt);
            let fast = mc.position_at_end(&z, t);
            assert!(
                (fast - reference).norm() < 1e-12,
                "{rate}: {fast} vs {reference}"
            );
        }
    }
}
