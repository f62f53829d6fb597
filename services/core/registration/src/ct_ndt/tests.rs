use super::*;
use crate::error::RegistrationError;
use crate::ndt::register_ndt;
use crate::params::NdtParams;
use crate::test_support::{map, perturb, rng, target, true_t_sensor_target};
use nalgebra::Vector3;
use nalgebra::Vector6;
use rand::RngExt;
use spacepose_geometry::{Point, Pose, so3};

fn random_pose(rng: &mut rand_chacha::ChaCha8Rng, angle_scale: f64) -> Pose {
    let mut v = || {
        Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
    };
    Pose::new(so3::exp(&(v() * angle_scale)), v() * 5.0)
}

#[test]
fn interpolation_hits_both_ends_and_the_middle() {
    let mut rng = rng(11);
    let (s, e) = (random_pose(&mut rng, 1.5), random_pose(&mut rng, 1.5));
    let (a0, d0) = interpolate(&s, &e, 0.0).error_to(&s);
    let (a1, d1) = interpolate(&s, &e, 1.0).error_to(&e);
    assert!(a0 < 1e-12 && d0 < 1e-12 && a1 < 1e-9 && d1 < 1e-12);
    let mid = interpolate(&s, &e, 0.5);
    let half_way = so3::distance(&s.rotation, &mid.rotation);
    assert!((half_way - 0.5 * so3::distance(&s.rotation, &e.rotation)).abs() < 1e-12);
}

#[test]
fn jacobian_eq_15_agrees_with_finite_differences() {
    let mut rng = rng(12);
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for _ in 0..50 {
        let start = random_pose(&mut rng, 1.0);
        // End attitudes up to ~100° away from the start.
        let end = random_pose(&mut rng, 1.0).compose(&Pose::identity());
        let end = Pose::new(
            so3::exp(&(so3::log(&end.rotation) * 0.5)) * start.rotation,
            end.translation,
        );
        let u = rng.random_range(0.0..1.0);
        let z = Vector3::new(
            rng.random_range(-3.0..3.0),
            rng.random_range(-3.0..3.0),
            rng.random_range(2.0..9.0),
        );
        let analytic = ct_point_jacobian(&start, &end, u, &z);
        let f = |d: &Vector6<f64>| interpolate(&start, &end.oplus(d), u).transform(&z);
        for j in 0..6 {
            let mut d = Vector6::zeros();
            d[j] = h;
            let fd = (f(&d) - f(&(-d))) / (2.0 * h);
            let col = analytic.column(j);
            let rel = (fd - col).norm() / col.norm().max(1e-3);
            worst = worst.max(rel);
        }
    }
    assert!(worst < 1e-6, "worst relative error {worst}");
}

/// A scan blurred by a fast tumble: the target turns 6° about its centre of
/// mass and drifts 4 cm between the start and the end of the scan.
fn blurred_scan() -> (Vec<Point>, Pose, Pose, ScanTimes) {
    let start = true_t_sensor_target().inverse();
    let mut rng = rng(13);
    let end = perturb(&start, 6f64.to_radians(), 0.04, &mut rng);
    let scan = ScanTimes {
        start_s: 10.0,
        end_s: 11.0,
    };
    let frame = target().blurred_frame(&start, &end, scan.start_s, scan.end_s, 0.02);
    (frame, start, end, scan)
}

#[test]
fn recovers_the_end_pose_of_a_blurred_frame_better_than_ndt() {
    let (frame, start, end, scan) = blurred_scan();
    let params = NdtParams::default();
    // Initial guess for the end pose: a filter prediction 2° / 2 cm off
    // (seed 000 Fig. 4), the same for both methods.
    let guess = perturb(&end, 2f64.to_radians(), 0.02, &mut rng(14));
    let ct = register_ct_ndt(map(), &frame, &scan, &start, &guess, &params).unwrap();
    let ndt = register_ndt(map(), &frame, &guess, &params).unwrap();
    let (ct_ang, ct_d) = ct.t_target_sensor.error_to(&end);
    let (ndt_ang, ndt_d) = ndt.t_target_sensor.error_to(&end);
    println!(
        "end-pose error: CT-NDT {:.4}° {:.2} mm ({} it), NDT {:.4}° {:.2} mm ({} it)",
        ct_ang.to_degrees(),
        ct_d * 1e3,
        ct.iterations,
        ndt_ang.to_degrees(),
        ndt_d * 1e3,
        ndt.iterations
    );
    assert!(ct.converged);
    assert!(ct_ang < ndt_ang / 3.0 && ct_d < ndt_d, "CT-NDT not better");
    // Within the smoothing bias of the Table 1 map (see the NDT tests).
    assert!(ct_ang.to_degrees() < 0.3 && ct_d < 0.02);
    assert!(ct.information.cholesky().is_some());
}

#[test]
fn bad_input_is_an_error_value() {
    let (frame, start, _, scan) = blurred_scan();
    let p = NdtParams::default();
    let reversed = ScanTimes {
        start_s: 2.0,
        end_s: 1.0,
    };
    assert!(matches!(
        register_ct_ndt(map(), &frame, &reversed, &start, &start, &p),
        Err(RegistrationError::InvalidParameter { .. })
    ));
    let nan_time = ScanTimes {
        start_s: f64::NAN,
        end_s: 1.0,
    };
    assert!(register_ct_ndt(map(), &frame, &nan_time, &start, &start, &p).is_err());
    assert!(matches!(
        register_ct_ndt(map(), &[], &scan, &start, &start, &p),
        Err(RegistrationError::EmptyCloud)
    ));
    let mut no_time = frame.clone();
    no_time.iter_mut().for_each(|q| q.t = f64::NAN);
    assert!(matches!(
        register_ct_ndt(map(), &no_time, &scan, &start, &start, &p),
        Err(RegistrationError::AllPointsNonFinite { .. })
    ));
    let far = Pose::new(
        start.rotation,
        start.translation + Vector3::new(0.0, 40.0, 0.0),
    );
    assert!(matches!(
        register_ct_ndt(map(), &frame, &scan, &far, &far, &p),
        Err(RegistrationError::NoCorrespondences { .. })
    ));
    let mut some_nan = frame.clone();
    some_nan[0].t = f64::INFINITY;
    some_nan[1].y = f32::NAN;
    let reg = register_ct_ndt(map(), &some_nan, &scan, &start, &start, &p).unwrap();
    assert_eq!(reg.skipped_non_finite, 2);
}

#[test]
fn exp_coefficients_series_meet_the_closed_form() {
    let closed = |theta2: f64| {
        let theta = theta2.sqrt();
        let (s, c) = theta.sin_cos();
        (
            s / theta,
            (1.0 - c) / theta2,
            (theta - s) / (theta2 * theta),
        )
    };
    for theta2 in [1e-6, 1e-3, 0.01, 0.039_999, 0.04, 0.1] {
        let (a, b, c) = super::interpolation::exp_coefficients(theta2);
        let (a0, b0, c0) = closed(theta2);
        // The closed forms of b and c lose digits to cancellation at small θ.
        let tol = if theta2 < 1e-3 { 1e-6 } else { 1e-12 };
        assert!((a - a0).abs() < 1e-14, "a at {theta2}");
        assert!((b - b0).abs() < tol, "b at {theta2}");
        assert!((c - c0).abs() < tol, "c at {theta2}: {c} vs {c0}");
    }
    assert_eq!(
        super::interpolation::exp_coefficients(0.0),
        (1.0, 0.5, 1.0 / 6.0)
    );
}
