//! Tests of `RelativeMotionFilter` (kept beside `filter.rs`).

use super::*;
use nalgebra::{Rotation3, Unit};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use spacepose_geometry::so3;

struct Truth {
    r0: Rotation3<f64>,
    p0: Vector3<f64>,
    v: Vector3<f64>,
    w_target: Vector3<f64>,
}

impl Truth {
    fn new() -> Self {
        Self {
            r0: so3::exp(&Vector3::new(0.2, 0.9, -0.4)),
            p0: Vector3::new(0.4, -0.3, 25.0),
            v: Vector3::new(0.02, 0.01, -0.15),
            w_target: Unit::new_normalize(Vector3::new(0.3, -0.5, 0.8)).into_inner()
                * 10f64.to_radians(),
        }
    }
    fn pose(&self, t: f64) -> Pose {
        Pose::new(
            self.r0 * so3::exp(&(self.w_target * t)),
            self.p0 + self.v * t,
        )
    }
}

fn noisy(pose: &Pose, rng: &mut ChaCha8Rng, s_rot: f64, s_pos: f64) -> Pose {
    let nr = Normal::new(0.0, s_rot).unwrap();
    let np = Normal::new(0.0, s_pos).unwrap();
    let d = nalgebra::Vector6::from_fn(|i, _| {
        if i < 3 {
            nr.sample(rng)
        } else {
            np.sample(rng)
        }
    });
    pose.oplus(&d)
}

fn config() -> FilterConfig {
    // The truth moves at constant velocity: token process noise only.
    FilterConfig {
        q_pos: 1e-8,
        q_rot: 1e-10,
        q_w: 1e-10,
        q_w_sensor: 1e-10,
        sigma_rot_deg: 0.5,
        sigma_pos_m: 0.01,
        // The χ² gate of the filter library, tested below.
        gate_mahalanobis2: Some(22.46),
        ..Default::default()
    }
}

/// A filter fed `n` noisy 1 Hz measurements of `truth`, started at ω = v = 0.
fn converged(truth: &Truth, n: usize, rng: &mut ChaCha8Rng) -> RelativeMotionFilter {
    let mut f = RelativeMotionFilter::new(config()).unwrap();
    let (s_rot, s_pos) = (0.5f64.to_radians(), 0.01);
    f.initialize(
        0.0,
        &noisy(&truth.pose(0.0), rng, s_rot, s_pos),
        Vector3::zeros(),
        Vector3::zeros(),
    )
    .unwrap();
    for k in 1..=n {
        let t = k as f64;
        let out = f
            .update(t, &noisy(&truth.pose(t), rng, s_rot, s_pos), None)
            .unwrap();
        assert!(out.accepted && out.fused, "update {k} rejected: {out:?}");
    }
    f
}

#[test]
fn predict_at_follows_constant_velocity_motion() {
    let truth = Truth::new();
    let mut f = RelativeMotionFilter::new(config()).unwrap();
    f.initialize(2.0, &truth.pose(2.0), truth.v, truth.w_target)
        .unwrap();
    let before = f.estimate().unwrap();
    for dt in [0.0, 0.1, 1.0, 7.3] {
        let pr = f.predict_at(2.0 + dt).unwrap();
        let (e_rot, e_pos) = pr.pose.error_to(&truth.pose(2.0 + dt));
        assert!(
            e_rot < 1e-12 && e_pos < 1e-12,
            "Δt = {dt}: {e_rot} rad, {e_pos} m"
        );
        assert_eq!(pr.t, 2.0 + dt);
        assert!((pr.w_sensor() - pr.pose.rotation * truth.w_target).norm() < 1e-15);
        if dt > 0.0 {
            assert!(pr.covariance.trace() > before.covariance.trace());
        }
    }
    // Predicting does not move the filter.
    assert_eq!(f.estimate().unwrap(), before);
    assert_eq!(f.time(), Some(2.0));
}

#[test]
fn converged_filter_predicts_the_motion() {
    let truth = Truth::new();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let f = converged(&truth, 20, &mut rng);
    let est = f.estimate().unwrap();
    let w_err = (est.w_target - truth.w_target).norm().to_degrees();
    let v_err = (est.v_sensor - truth.v).norm();
    let pr = f.predict_at(22.5).unwrap();
    let (e_rot, e_pos) = pr.pose.error_to(&truth.pose(22.5));
    println!(
        "filter after 20 updates: |ω̂-ω| = {w_err:.3} deg/s, |v̂-v| = {v_err:.2e} m/s; \
         prediction 2.5 s ahead: {:.3} deg, {:.4} m",
        e_rot.to_degrees(),
        e_pos
    );
    assert!(w_err < 0.2, "{w_err}");
    assert!(v_err < 3e-3, "{v_err}");
    assert!(e_rot.to_degrees() < 1.0 && e_pos < 0.02);
}

#[test]
fn gate_flags_a_30_degree_outlier() {
    let truth = Truth::new();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut f = converged(&truth, 10, &mut rng);
    let before = f.estimate().unwrap();
    let outlier = truth.pose(11.0).oplus(&nalgebra::Vector6::new(
        0.0,
        30f64.to_radians(),
        0.0,
        0.0,
        0.0,
        0.0,
    ));
    let out = f.update(11.0, &outlier, None).unwrap();
    println!(
        "30° outlier: innovation {:.2} deg, d² = {:.1} (gate {:?})",
        out.innovation_rot_deg, out.mahalanobis2, out.gate_mahalanobis2
    );
    assert!(!out.accepted && !out.fused);
    assert!((out.innovation_rot_deg - 30.0).abs() < 2.0);
    assert_eq!(out.consecutive_rejections, 1);
    assert_eq!(
        f.estimate().unwrap(),
        before,
        "a rejected measurement must not change the state"
    );
    // A consistent measurement afterwards is accepted again.
    let good = f.update(12.0, &truth.pose(12.0), None).unwrap();
    println!("next good measurement: d² = {:.2}", good.mahalanobis2);
    assert!(good.accepted && good.fused && good.consecutive_rejections == 0);
    // The caller may insist.
    let forced = f.force_update(13.0, &outlier, None).unwrap();
    assert!(!forced.accepted && forced.fused);
    assert_eq!(f.time(), Some(13.0));
}

#[test]
fn registration_covariance_is_used_when_given() {
    let truth = Truth::new();
    let mut f = RelativeMotionFilter::new(config()).unwrap();
    f.initialize(0.0, &truth.pose(0.0), truth.v, truth.w_target)
        .unwrap();
    let info = Matrix6::from_diagonal(&nalgebra::Vector6::new(1e4, 1e4, 1e4, 1e6, 1e6, 1e6));
    let cov = covariance_from_information(&info).unwrap();
    assert!((cov * info - Matrix6::identity()).abs().max() < 1e-12);
    let mut g = f.clone();
    let out = f.update(1.0, &truth.pose(1.0), Some(cov)).unwrap();
    assert!(out.used_registration_covariance);
    let out_fixed = g.update(1.0, &truth.pose(1.0), None).unwrap();
    assert!(!out_fixed.used_registration_covariance);
    // σ_pos = 1 mm (registration) versus 1 cm (fixed): tighter posterior.
    let (pf, pg) = (f.estimate().unwrap(), g.estimate().unwrap());
    assert!(pf.covariance[(3, 3)] < pg.covariance[(3, 3)]);
    // Config can force the fixed noise.
    let c = FilterConfig {
        use_registration_covariance: false,
        ..config()
    };
    let mut h = RelativeMotionFilter::new(c).unwrap();
    h.initialize(0.0, &truth.pose(0.0), truth.v, truth.w_target)
        .unwrap();
    assert!(
        !h.update(1.0, &truth.pose(1.0), Some(cov))
            .unwrap()
            .used_registration_covariance
    );
}

#[test]
fn bad_input_is_an_error() {
    let truth = Truth::new();
    let mut f = RelativeMotionFilter::new(config()).unwrap();
    assert_eq!(f.predict_at(1.0), Err(FilterError::NotInitialized));
    assert_eq!(
        f.update(1.0, &truth.pose(1.0), None),
        Err(FilterError::NotInitialized)
    );
    f.initialize(1.0, &truth.pose(1.0), Vector3::zeros(), Vector3::zeros())
        .unwrap();
    assert!(matches!(
        f.update(1.0, &truth.pose(1.0), None),
        Err(FilterError::InvalidTimeStep { .. })
    ));
    assert!(matches!(
        f.update(0.5, &truth.pose(1.0), None),
        Err(FilterError::InvalidTimeStep { .. })
    ));
    assert!(matches!(
        f.predict_at(0.5),
        Err(FilterError::InvalidTimeStep { .. })
    ));
    assert!(matches!(
        f.predict_at(f64::NAN),
        Err(FilterError::NonFinite { .. })
    ));
    let mut nan_pose = truth.pose(2.0);
    nan_pose.translation.x = f64::NAN;
    assert!(matches!(
        f.update(2.0, &nan_pose, None),
        Err(FilterError::NonFinite { .. })
    ));
    let nan_cov = Matrix6::from_element(f64::NAN);
    assert!(f.update(2.0, &truth.pose(2.0), Some(nan_cov)).is_err());
    assert!(
        f.update(2.0, &truth.pose(2.0), Some(-Matrix6::identity()))
            .is_err()
    );
    assert!(covariance_from_information(&Matrix6::zeros()).is_err());
    assert!(
        f.initialize(
            f64::INFINITY,
            &truth.pose(0.0),
            Vector3::zeros(),
            Vector3::zeros()
        )
        .is_err()
    );
    assert!(
        RelativeMotionFilter::new(FilterConfig {
            q_pos: f64::NAN,
            ..config()
        })
        .is_err()
    );
    // Errors leave the state untouched and usable.
    assert_eq!(f.time(), Some(1.0));
    assert!(f.update(2.0, &truth.pose(2.0), None).unwrap().fused);
}

#[test]
fn restore_reproduces_the_published_estimate() {
    use nalgebra::Vector3;
    let mut source = RelativeMotionFilter::new(FilterConfig::default()).unwrap();
    let pose = Pose::new(
        spacepose_geometry::so3::exp(&Vector3::new(0.1, 0.2, -0.3)),
        Vector3::new(0.5, -0.2, 10.0),
    );
    source
        .initialize(
            1.0,
            &pose,
            Vector3::new(0.0, 0.0, -0.02),
            Vector3::new(0.0, 0.17, 0.0),
        )
        .unwrap();
    let moved = Pose::new(
        pose.rotation * spacepose_geometry::so3::exp(&Vector3::new(0.0, 0.17, 0.0)),
        Vector3::new(0.5, -0.2, 9.98),
    );
    source.update(2.0, &moved, None).unwrap();
    let published = source.estimate().unwrap();
    let mut copy = RelativeMotionFilter::new(FilterConfig::default()).unwrap();
    copy.restore(&published).unwrap();
    let a = source.predict_at(3.5).unwrap();
    let b = copy.predict_at(3.5).unwrap();
    assert!(a.pose.error_to(&b.pose).0 < 1e-12 && a.pose.error_to(&b.pose).1 < 1e-12);
    assert!((a.covariance - b.covariance).norm() < 1e-12);
    let mut bad = published;
    bad.t = f64::NAN;
    assert!(copy.restore(&bad).is_err());
}

/// The NIS of measurements drawn from the stated noise follows χ²(6)
/// (mean 6); measurements 3 times noisier than stated give about 9 times
/// that. `innovation` is the update's own figure and changes nothing.
#[test]
fn nis_of_consistent_measurements_averages_six() {
    let truth = Truth::new();
    let (s_rot, s_pos) = (0.5f64.to_radians(), 0.01);
    let mean_nis = |k_noise: f64, seed: u64| {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut f = converged(&truth, 20, &mut rng);
        let mut sum = 0.0;
        for k in 21..=420 {
            let t = k as f64;
            let m = noisy(&truth.pose(t), &mut rng, k_noise * s_rot, k_noise * s_pos);
            let before = f.estimate().unwrap();
            let nis = f.innovation(t, &m, None).unwrap().mahalanobis2;
            assert_eq!(f.estimate().unwrap(), before);
            let out = f.force_update(t, &m, None).unwrap();
            assert_eq!(out.mahalanobis2, nis);
            sum += nis;
        }
        sum / 400.0
    };
    let consistent = mean_nis(1.0, 21);
    assert!((consistent - 6.0).abs() < 0.8, "mean NIS {consistent}");
    let over = mean_nis(3.0, 22);
    assert!(over > 30.0, "mean NIS {over} with 3× the stated noise");
}
