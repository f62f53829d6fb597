//! Tests of the attitude IEKF (kept beside `attitude.rs`).

use super::*;
use nalgebra::Unit;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

fn deg(x: f64) -> f64 {
    x.to_radians()
}

fn tilted_axis() -> Unit<Vector3<f64>> {
    Unit::new_normalize(Vector3::new(0.3, -0.5, 0.8))
}

fn some_attitude() -> Rotation3<f64> {
    so3::exp(&Vector3::new(0.4, -1.1, 0.7))
}

/// The error `ξ` of a "true" state with respect to an estimate.
fn error_of(
    r: &Rotation3<f64>,
    w: &Vector3<f64>,
    r_hat: &Rotation3<f64>,
    w_hat: &Vector3<f64>,
) -> nalgebra::Vector6<f64> {
    let xr = so3::log(&(r * r_hat.inverse()));
    let xw = w - w_hat;
    nalgebra::Vector6::new(xr.x, xr.y, xr.z, xw.x, xw.y, xw.z)
}

#[test]
fn right_jacobian_is_the_derivative_of_exp() {
    let x = Vector3::new(0.7, -0.4, 1.2);
    let d = Vector3::new(1e-6, -2e-6, 1.5e-6);
    let lhs = so3::exp(&(x + d));
    let rhs = so3::exp(&x) * so3::exp(&(right_jacobian(&x) * d));
    assert!(so3::distance(&lhs, &rhs) < 1e-11);
    // Without the Jacobian the error is first order.
    assert!(so3::distance(&lhs, &(so3::exp(&x) * so3::exp(&d))) > 1e-7);
}

#[test]
fn f_matches_numerical_linearisation() {
    // ω̂ Δt = 60°, so J_r is far from the identity.
    let w_hat = tilted_axis().into_inner() * deg(40.0);
    let dt = 1.5;
    let est = AttitudeFilter::new(some_attitude(), w_hat, Matrix6::identity()).unwrap();
    let r_pred = est.predicted_rotation(dt);
    let h = 1e-6;
    let mut f_num = Matrix6::zeros();
    for j in 0..6 {
        let mut col = nalgebra::Vector6::zeros();
        for sign in [1.0, -1.0] {
            let mut xi = nalgebra::Vector6::zeros();
            xi[j] = sign * h;
            let r = so3::exp(&xi.fixed_rows::<3>(0).into_owned()) * est.r_sensor_target;
            let w = w_hat + xi.fixed_rows::<3>(3);
            let r_next = r * so3::exp(&(w * dt)); // Eq. (9), true state
            col += error_of(&r_next, &w, &r_pred, &w_hat) * sign / (2.0 * h);
        }
        f_num.set_column(j, &col);
    }
    let f = est.transition_matrix(dt);
    let diff = (f - f_num).abs().max();
    println!("IEKF F vs numerical linearisation: max |ΔF| = {diff:.2e}");
    assert!(
        diff < 1e-7,
        "F differs from finite differences by {diff}\nF = {f}\nnum = {f_num}"
    );
    // A plain `R̂⁻ Δt` coupling (without J_r) would be visibly wrong here.
    let mut f_naive = Matrix6::identity();
    f_naive
        .fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(r_pred.matrix() * dt));
    assert!((f_naive - f_num).abs().max() > 1e-2);
}

#[test]
fn process_noise_is_positive_semidefinite() {
    let est = AttitudeFilter::new(
        some_attitude(),
        tilted_axis().into_inner() * 0.5,
        Matrix6::identity(),
    )
    .unwrap();
    for &(q_rot, q_w) in &[(1e-6, 1e-6), (0.0, 1e-4), (1e-4, 0.0)] {
        let q = est.process_noise(0.8, q_rot, q_w);
        let min_eig = q.symmetric_eigenvalues().min();
        assert!(min_eig > -1e-15, "min eigenvalue {min_eig}");
        assert_eq!(q, q.transpose());
    }
}

/// Runs the convergence scenario with one noise seed; returns the filter
/// after 20 updates and the per-update |ω̂ - ω| (deg/s).
fn run_convergence(seed: u64) -> (AttitudeFilter, Vec<f64>, Rotation3<f64>) {
    // Truth: ω = 10°/s about a tilted axis (target frame), 1 Hz attitude
    // measurements with σ = 0.5° per axis; the filter starts at ω̂ = 0.
    let w_true = tilted_axis().into_inner() * deg(10.0);
    let r0 = some_attitude();
    let sigma = deg(0.5);
    let n = Matrix3::identity() * sigma * sigma;
    let noise = Normal::new(0.0, sigma).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut meas =
        |r: Rotation3<f64>| so3::exp(&Vector3::from_fn(|_, _| noise.sample(&mut rng))) * r;

    let mut p0 = Matrix6::zeros();
    p0.fixed_view_mut::<3, 3>(0, 0).copy_from(&n);
    p0.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&(Matrix3::identity() * deg(30.0).powi(2)));
    let mut f = AttitudeFilter::new(meas(r0), Vector3::zeros(), p0).unwrap();
    // The truth has constant ω: only a token process noise.
    let (q_rot, q_w) = (1e-10, 1e-10);
    let mut w_errs = Vec::new();
    let mut r_true = r0;
    for k in 1..=20 {
        r_true = r0 * so3::exp(&(w_true * k as f64));
        f = f.predict(1.0, q_rot, q_w).unwrap();
        f.update(&meas(r_true), &n).unwrap();
        assert!(f.covariance.cholesky().is_some());
        w_errs.push((f.w_target - w_true).norm().to_degrees());
    }
    (f, w_errs, r_true)
}

#[test]
fn converges_to_constant_angular_velocity() {
    let w_true = tilted_axis().into_inner() * deg(10.0);
    let (f, w_errs, r_true) = run_convergence(11);
    let rounded: Vec<f64> = w_errs
        .iter()
        .map(|e| (e * 1000.0).round() / 1000.0)
        .collect();
    println!("IEKF |ω̂-ω| (deg/s) per update, seed 11: {rounded:?}");
    let r_err = so3::distance(&f.r_sensor_target, &r_true).to_degrees();
    println!(
        "IEKF after 20 updates: |ω̂-ω| = {:.4} deg/s, attitude error = {r_err:.3} deg",
        w_errs[19]
    );
    assert!(
        w_errs[19] < 0.2,
        "angular-velocity error {} deg/s",
        w_errs[19]
    );
    assert!(r_err < 1.0, "attitude error {r_err} deg");
    // Consistency: the error lies within the filter's own bounds (NEES, 3 dof).
    let dw = f.w_target - w_true;
    let p_ww = f.covariance.fixed_view::<3, 3>(3, 3).into_owned();
    let nees = dw.dot(&(p_ww.try_inverse().unwrap() * dw));
    assert!(nees < 16.3, "ω NEES {nees} (χ²₃ 99.9 % = 16.3)");
    // Not a lucky seed: every one of 20 noise draws converges.
    let worst = (100..120)
        .map(|s| run_convergence(s).1[19])
        .fold(0.0, f64::max);
    println!("IEKF worst |ω̂-ω| after 20 updates over 20 seeds: {worst:.4} deg/s");
    assert!(worst < 0.2, "worst seed {worst} deg/s");
}

#[test]
fn rejects_bad_input() {
    let f = AttitudeFilter::new(some_attitude(), Vector3::zeros(), Matrix6::identity()).unwrap();
    assert!(f.predict(-1.0, 1e-6, 1e-6).is_err());
    assert!(f.predict(1.0, f64::NAN, 1e-6).is_err());
    let bad = Rotation3::from_matrix_unchecked(Matrix3::from_element(f64::NAN));
    assert!(f.innovation(&bad, &Matrix3::identity()).is_err());
    assert!(f.innovation(&some_attitude(), &Matrix3::zeros()).is_err());
    assert!(
        AttitudeFilter::new(
            some_attitude(),
            Vector3::new(f64::INFINITY, 0.0, 0.0),
            Matrix6::identity()
        )
        .is_err()
    );
}
