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

type Vector9 = nalgebra::SVector<f64, 9>;

const NOISE: AttitudeNoise = AttitudeNoise {
    q_rot: 1e-6,
    q_w: 1e-6,
    q_w_sensor: 1e-6,
};

fn stack(a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>) -> Vector9 {
    Vector9::from_iterator(a.iter().chain(b.iter()).chain(c.iter()).copied())
}

/// A state far from the identity in every part: ω̂ Δt = 60° and
/// Ω̂ Δt = 9° at Δt = 1.5 s.
fn some_filter(sensor_rate: bool) -> AttitudeFilter {
    let w = tilted_axis().into_inner() * deg(40.0);
    let big_w = Vector3::new(-0.2, 0.9, 0.4).normalize() * deg(6.0);
    AttitudeFilter::new(
        some_attitude(),
        w,
        if sensor_rate { big_w } else { Vector3::zeros() },
        Matrix9::identity(),
        sensor_rate,
    )
    .unwrap()
}

/// `est` moved by the kept error `ξ = [ξ_R; ξ_u; ξ_Ω]` (module docs).
fn perturbed(est: &AttitudeFilter, xi: &Vector9) -> AttitudeFilter {
    AttitudeFilter {
        r_sensor_target: so3::exp(&xi.fixed_rows::<3>(0).into_owned()) * est.r_sensor_target,
        w_target: est.w_target + xi.fixed_rows::<3>(3),
        w_inertial_sensor: est.w_inertial_sensor + xi.fixed_rows::<3>(6),
        ..*est
    }
}

/// `est` moved by the error `[ξ_R; ξ_ω; ξ_Ω]` of the derivation.
fn perturbed_inertial(est: &AttitudeFilter, xi: &Vector9) -> AttitudeFilter {
    let r = so3::exp(&xi.fixed_rows::<3>(0).into_owned()) * est.r_sensor_target;
    let w = est.w_inertial_target() + xi.fixed_rows::<3>(3);
    let big_w = est.w_inertial_sensor + xi.fixed_rows::<3>(6);
    AttitudeFilter {
        r_sensor_target: r,
        w_target: w - r.inverse() * big_w,
        w_inertial_sensor: big_w,
        ..*est
    }
}

/// The error of `x` from `est` in `[ξ_R; ξ_ω; ξ_Ω]` or, with `kept`, in
/// `[ξ_R; ξ_u; ξ_Ω]`.
fn error_of(x: &AttitudeFilter, est: &AttitudeFilter, kept: bool) -> Vector9 {
    let xr = so3::log(&(x.r_sensor_target * est.r_sensor_target.inverse()));
    let dw = if kept {
        x.w_target - est.w_target
    } else {
        x.w_inertial_target() - est.w_inertial_target()
    };
    stack(&xr, &dw, &(x.w_inertial_sensor - est.w_inertial_sensor))
}

/// The Jacobian of `g(ξ)` at 0 by central differences.
fn numerical_jacobian(g: impl Fn(&Vector9) -> Vector9) -> Matrix9 {
    let h = 1e-6;
    let mut j = Matrix9::zeros();
    for c in 0..9 {
        let mut xi = Vector9::zeros();
        xi[c] = h;
        j.set_column(c, &((g(&xi) - g(&-xi)) / (2.0 * h)));
    }
    j
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
    let dt = 1.5;
    for sensor_rate in [true, false] {
        let est = some_filter(sensor_rate);
        let pred = est.predict(dt, &NOISE).unwrap();
        // The derivation's F, in [ξ_R; ξ_ω; ξ_Ω].
        let inertial = numerical_jacobian(|xi| {
            let next = perturbed_inertial(&est, xi).predict(dt, &NOISE).unwrap();
            error_of(&next, &pred, false)
        });
        // The kept state's, in [ξ_R; ξ_u; ξ_Ω].
        let kept = numerical_jacobian(|xi| {
            let next = perturbed(&est, xi).predict(dt, &NOISE).unwrap();
            error_of(&next, &pred, true)
        });
        for (name, f, mut f_num) in [
            ("F", est.inertial_transition(dt), inertial),
            ("F_pub", est.transition_matrix(dt), kept),
        ] {
            if !sensor_rate {
                // Ω is not a state then: nothing couples to it.
                f_num.fixed_columns_mut::<3>(6).fill(0.0);
                f_num[(6, 6)] = 1.0;
                f_num[(7, 7)] = 1.0;
                f_num[(8, 8)] = 1.0;
            }
            let diff = (f - f_num).abs().max();
            println!(
                "{name} vs finite differences (sensor rate {sensor_rate}): max |ΔF| = {diff:.2e}"
            );
            assert!(diff < 1e-6, "{name} = {f}\nnumerical = {f_num}");
        }
    }
    // A plain `R̂⁻ Δt` coupling (without J_r) would be visibly wrong here.
    let est = some_filter(true);
    let mut f_naive = est.inertial_transition(1.5);
    f_naive
        .fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(est.predicted_rotation(1.5).matrix() * 1.5));
    assert!((f_naive - est.inertial_transition(1.5)).abs().max() > 1e-2);
}

#[test]
fn t_maps_the_inertial_error_to_the_kept_one() {
    let est = some_filter(true);
    let t_num = numerical_jacobian(|xi| error_of(&perturbed_inertial(&est, xi), &est, true));
    let t = est.error_map(&est.r_sensor_target, false);
    assert!(
        (t - t_num).abs().max() < 1e-7,
        "T = {t}\nnumerical = {t_num}"
    );
    let t_inv = est.error_map(&est.r_sensor_target, true);
    assert!((t * t_inv - Matrix9::identity()).abs().max() < 1e-12);
    // Off: u = ω and T = I.
    let off = some_filter(false);
    assert_eq!(off.w_target, off.w_inertial_target());
    assert_eq!(
        off.error_map(&off.r_sensor_target, false),
        Matrix9::identity()
    );
}

#[test]
fn process_noise_is_positive_semidefinite() {
    let est = some_filter(true);
    let cases = [(1e-6, 1e-6, 1e-6), (0.0, 1e-4, 0.0), (1e-4, 0.0, 1e-5)];
    for (q_rot, q_w, q_w_sensor) in cases {
        let noise = AttitudeNoise {
            q_rot,
            q_w,
            q_w_sensor,
        };
        let q = est.process_noise(0.8, &noise);
        let min_eig = q.symmetric_eigenvalues().min();
        assert!(min_eig > -1e-15, "min eigenvalue {min_eig}");
        assert_eq!(q, q.transpose());
    }
}

/// The truth of the convergence runs: `R(t) = Exp(-Ω t) R0 Exp(ω t)`.
struct Truth {
    r0: Rotation3<f64>,
    w: Vector3<f64>,
    big_w: Vector3<f64>,
}

impl Truth {
    fn r(&self, t: f64) -> Rotation3<f64> {
        so3::exp(&(-self.big_w * t)) * self.r0 * so3::exp(&(self.w * t))
    }

    fn u(&self, t: f64) -> Vector3<f64> {
        self.w - self.r(t).inverse() * self.big_w
    }
}

/// Runs the convergence scenario with one noise seed: 1 Hz attitude
/// measurements with σ = 0.5° per axis of a target turning at 10°/s about a
/// tilted axis, seen from a sensor frame turning at `sensor_degps`; the
/// filter starts at rest. Returns the filter after 30 updates, the
/// per-update |û - u| (deg/s) and the truth.
fn run_convergence(
    seed: u64,
    sensor_degps: f64,
    sensor_rate: bool,
) -> (AttitudeFilter, Vec<f64>, Truth) {
    let truth = Truth {
        r0: some_attitude(),
        w: tilted_axis().into_inner() * deg(10.0),
        big_w: Vector3::new(0.1, 0.3, -0.9).normalize() * deg(sensor_degps),
    };
    let sigma = deg(0.5);
    let n = Matrix3::identity() * sigma * sigma;
    let noise = Normal::new(0.0, sigma).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut meas =
        |r: Rotation3<f64>| so3::exp(&Vector3::from_fn(|_, _| noise.sample(&mut rng))) * r;
    let mut p0 = Matrix9::zeros();
    p0.fixed_view_mut::<3, 3>(0, 0).copy_from(&n);
    for (i, s) in [(3, 30.0), (6, 2.0)] {
        p0.fixed_view_mut::<3, 3>(i, i)
            .copy_from(&(Matrix3::identity() * deg(s).powi(2)));
    }
    let mut f = AttitudeFilter::new(
        meas(truth.r(0.0)),
        Vector3::zeros(),
        Vector3::zeros(),
        p0,
        sensor_rate,
    )
    .unwrap();
    // The truth has constant rates: only a token process noise.
    let token = AttitudeNoise {
        q_rot: 1e-10,
        q_w: 1e-10,
        q_w_sensor: 1e-10,
    };
    let mut w_errs = Vec::new();
    for k in 1..=30 {
        let t = k as f64;
        f = f.predict(1.0, &token).unwrap();
        f.update(&meas(truth.r(t)), &n).unwrap();
        assert!(f.covariance.cholesky().is_some());
        w_errs.push((f.w_target - truth.u(t)).norm().to_degrees());
    }
    (f, w_errs, truth)
}

#[test]
fn converges_to_constant_angular_velocity() {
    let (f, w_errs, truth) = run_convergence(11, 0.0, true);
    let rounded: Vec<f64> = w_errs
        .iter()
        .map(|e| (e * 1000.0).round() / 1000.0)
        .collect();
    println!("IEKF |û-u| (deg/s) per update, seed 11: {rounded:?}");
    let r_err = so3::distance(&f.r_sensor_target, &truth.r(30.0)).to_degrees();
    println!(
        "IEKF after 30 updates: |û-u| = {:.4} deg/s, attitude error = {r_err:.3} deg",
        w_errs[29]
    );
    assert!(
        w_errs[29] < 0.2,
        "angular-velocity error {} deg/s",
        w_errs[29]
    );
    assert!(r_err < 1.0, "attitude error {r_err} deg");
    // Consistency: the error lies within the filter's own bounds (NEES, 3 dof).
    let du = f.w_target - truth.u(30.0);
    let p_uu = f.covariance.fixed_view::<3, 3>(3, 3).into_owned();
    let nees = du.dot(&(p_uu.try_inverse().unwrap() * du));
    assert!(nees < 16.3, "u NEES {nees} (χ²₃ 99.9 % = 16.3)");
    // Not a lucky seed: every one of 20 noise draws converges.
    let worst = (100..120)
        .map(|s| run_convergence(s, 0.0, true).1[29])
        .fold(0.0, f64::max);
    println!("IEKF worst |û-u| after 30 updates over 20 seeds: {worst:.4} deg/s");
    assert!(worst < 0.2, "worst seed {worst} deg/s");
}

#[test]
fn a_turning_sensor_frame_is_learnt_and_predicted() {
    // The sensor frame turns at 2°/s: the relative rate in the target frame
    // then changes as the target turns. Over 20 seeds, the prediction 5 s
    // ahead after 30 updates, with and without the sensor frame's rate.
    let mut worst = [0.0_f64; 2];
    for seed in 200..220 {
        for (i, on) in [true, false].into_iter().enumerate() {
            let (f, _, truth) = run_convergence(seed, 2.0, on);
            let token = AttitudeNoise {
                q_rot: 0.0,
                q_w: 0.0,
                q_w_sensor: 0.0,
            };
            let ahead = f.predict(5.0, &token).unwrap();
            let err = so3::distance(&ahead.r_sensor_target, &truth.r(35.0)).to_degrees();
            worst[i] = worst[i].max(err);
        }
    }
    println!(
        "5 s prediction, worst over 20 seeds: with Ω {:.3}°, without {:.3}°",
        worst[0], worst[1]
    );
    assert!(
        worst[0] < 2.0,
        "with the sensor frame's rate: {}°",
        worst[0]
    );
    assert!(worst[1] > 5.0 * worst[0], "without it: {}°", worst[1]);
}

#[test]
fn rejects_bad_input() {
    let f = some_filter(true);
    assert!(f.predict(-1.0, &NOISE).is_err());
    let nan = AttitudeNoise {
        q_w_sensor: f64::NAN,
        ..NOISE
    };
    assert!(f.predict(1.0, &nan).is_err());
    let bad = Rotation3::from_matrix_unchecked(Matrix3::from_element(f64::NAN));
    assert!(f.innovation(&bad, &Matrix3::identity()).is_err());
    assert!(f.innovation(&some_attitude(), &Matrix3::zeros()).is_err());
    let (zero, w_inf) = (Vector3::zeros(), Vector3::new(f64::INFINITY, 0.0, 0.0));
    let bad_states = [
        (w_inf, zero, Matrix9::identity()),
        (zero, w_inf, Matrix9::identity()),
        (zero, zero, -Matrix9::identity()),
    ];
    for (w, big_w, p) in bad_states {
        assert!(AttitudeFilter::new(some_attitude(), w, big_w, p, true).is_err());
    }
}

#[test]
fn off_keeps_the_sensor_frame_at_rest_and_uncoupled() {
    let mut f = some_filter(false);
    for _ in 0..5 {
        f = f.predict(1.0, &NOISE).unwrap();
        f.update(&some_attitude(), &(Matrix3::identity() * 1e-4))
            .unwrap();
    }
    assert_eq!(f.w_inertial_sensor, Vector3::zeros());
    assert_eq!(f.covariance.fixed_view::<6, 3>(0, 6).abs().max(), 0.0);
}
