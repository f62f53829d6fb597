use super::*;
use nalgebra::Matrix6;

/// Seeded noise in [-1, 1] (a small LCG: no extra dependency).
struct Noise(u64);
impl Noise {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
    fn vector(&mut self, scale: f64) -> Vector3<f64> {
        Vector3::new(self.next(), self.next(), self.next()) * scale
    }
}

/// `t_target_sensor` of a target turning at the constant body rate `w`
/// (target frame) in front of a fixed sensor: `R_ts(t) = Exp(−w t) R_ts(0)`.
fn truth(t: f64, w: &Vector3<f64>) -> Pose {
    let r0 = so3::exp(&Vector3::new(0.3, -1.1, 0.7));
    Pose::new(so3::exp(&(-w * t)) * r0, Vector3::new(0.1, -0.2, 3.0))
}

/// Records the exact poses of frames `ks` (1 s apart) of a target turning
/// at 0.1 rad/s about x, all with weakest lever arm `lever_m`, none held.
fn record_truth(held: &mut HeldRotation, ks: std::ops::Range<i32>, lever_m: f64) {
    let w = Vector3::new(0.1, 0.0, 0.0);
    for k in ks {
        held.record(f64::from(k), &truth(f64::from(k), &w), lever_m, false);
    }
}

/// Angle between the rotations of two poses (deg).
fn err_deg(a: &Pose, b: &Pose) -> f64 {
    so3::distance(&a.rotation, &b.rotation).to_degrees()
}

/// 60 s of well-constrained frames (0.2° of noise each), then a 150 s hold
/// (longer than the fit's window; one frame in 40 releases it) whose
/// results drift about the held axis at 0.085°/s (what the filter's rate
/// error did on seed 1): the corrected results stay within 0.5° of the
/// truth, where the drift alone reaches 12.8°.
#[test]
fn a_hold_follows_the_rate_fitted_before_it() {
    let w = Vector3::new(10f64.to_radians(), 1f64.to_radians(), 0.0);
    let axis = Vector3::x();
    let mut held = HeldRotation::new(HeldRotationConfig::default());
    let mut noise = Noise(5);
    for k in 0..=60 {
        let t = f64::from(k);
        let mut p = truth(t, &w);
        p.rotation = so3::exp(&noise.vector(0.2f64.to_radians())) * p.rotation;
        held.record(t, &p, 0.08, false);
    }
    let info = Matrix6::identity();
    let (mut worst, mut worst_uncorrected) = (0.0f64, 0.0f64);
    for k in 61..=210 {
        let t = f64::from(k);
        let true_pose = truth(t, &w);
        // The registration held the roll at a drifting prediction.
        let drift = (0.085f64 * (t - 60.0)).to_radians();
        let mut result = true_pose;
        result.rotation = so3::exp(&(axis * drift)) * result.rotation;
        worst_uncorrected = worst_uncorrected.max(err_deg(&result, &true_pose));
        let c = held.correct(t, &mut result, &axis, &info).expect("a fit");
        // The rate of the angle of t_target_sensor is −10°/s about x.
        assert!((c.rate_rad_s.to_degrees() + 10.0).abs() < 0.01, "{c:?}");
        worst = worst.max(err_deg(&result, &true_pose));
        held.record(t, &result, 0.04, k % 40 != 0);
    }
    println!("max error {worst:.3}° (uncorrected {worst_uncorrected:.2}°)");
    assert!(worst_uncorrected > 12.0);
    assert!(worst < 0.5, "{worst}");
}

/// Without enough well-constrained frames (short history, or all below
/// the lever arm) nothing is corrected.
#[test]
fn no_fit_without_enough_constrained_frames() {
    let w = Vector3::new(0.1, 0.0, 0.0);
    let info = Matrix6::identity();
    let mut held = HeldRotation::new(HeldRotationConfig::default());
    record_truth(&mut held, 0..10, 0.08);
    let mut p = truth(10.0, &w);
    let before = p;
    assert!(held.correct(10.0, &mut p, &Vector3::x(), &info).is_none());
    assert_eq!(p, before);
    let mut weak = HeldRotation::new(HeldRotationConfig::default());
    record_truth(&mut weak, 0..40, 0.03);
    assert!(weak.correct(40.0, &mut p, &Vector3::x(), &info).is_none());
}

/// A gap longer than `max_gap_s` starts the history again.
#[test]
fn a_gap_restarts_the_history() {
    let w = Vector3::new(0.1, 0.0, 0.0);
    let info = Matrix6::identity();
    let mut held = HeldRotation::new(HeldRotationConfig::default());
    record_truth(&mut held, 0..40, 0.08);
    // 10 s without a fused frame, then only 5 frames.
    record_truth(&mut held, 50..55, 0.08);
    let mut p = truth(55.0, &w);
    assert!(held.correct(55.0, &mut p, &Vector3::x(), &info).is_none());
}

/// The turn carries the translation that keeps the surface fitted: with
/// coupled information, `δ_t = −H_tt⁻¹ H_tr δ_r`.
#[test]
fn the_turn_comes_with_the_schur_translation() {
    let w = Vector3::new(0.1, 0.0, 0.0);
    let mut held = HeldRotation::new(HeldRotationConfig::default());
    record_truth(&mut held, 0..30, 0.08);
    let mut info = Matrix6::identity() * 10.0;
    info[(3, 0)] = 2.0;
    info[(0, 3)] = 2.0;
    let mut p = truth(30.0, &w);
    p.rotation = so3::exp(&Vector3::new(0.05, 0.0, 0.0)) * p.rotation;
    let before = p;
    let c = held
        .correct(30.0, &mut p, &Vector3::x(), &info)
        .expect("a fit");
    assert!((c.turn_rad + 0.05).abs() < 1e-6, "{c:?}");
    let dt = p.translation - before.translation;
    // −H_tt⁻¹ H_tr e_x · turn = −(2/10) · turn along x.
    assert!(
        (dt - Vector3::new(-0.2 * c.turn_rad, 0.0, 0.0)).norm() < 1e-12,
        "{dt}"
    );
}

#[test]
fn config_rejects_nan_and_out_of_domain_values() {
    assert!(HeldRotationConfig::default().invalid().is_none());
    let bad = [
        HeldRotationConfig {
            window_s: f64::NAN,
            ..Default::default()
        },
        HeldRotationConfig {
            min_lever_arm_m: f64::NAN,
            ..Default::default()
        },
        HeldRotationConfig {
            min_samples: 1,
            ..Default::default()
        },
        HeldRotationConfig {
            max_gap_s: 0.0,
            ..Default::default()
        },
    ];
    for c in bad {
        assert!(c.invalid().is_some(), "{c:?}");
    }
}

/// `held_at` and `weakest_rotation`, which `ndt` mode and the fitted rate use.
mod held_at_tests {
    use super::super::{held_at, weakest_rotation};
    use nalgebra::{Matrix6, Vector3, Vector6};
    use spacepose_geometry::Pose;
    use spacepose_registration::{Cost, Increment, Registration};

    /// A result at the identity that held `held` rotations, with geometric
    /// information `h`.
    fn held_result(held: usize, h: Matrix6<f64>) -> Registration {
        Registration {
            t_target_sensor: Pose::identity(),
            converged: true,
            iterations: 3,
            cost: Cost {
                total: 1.0,
                mean: 0.01,
            },
            inliers: 100,
            valid_points: 100,
            skipped_non_finite: 0,
            mean_squared_distance_m2: 1e-4,
            f_conv_m2: None,
            information: Matrix6::identity() * 7.0,
            last_increment: Increment::default(),
            degenerate_directions: held,
            weakest_lever_arm_m: 0.01,
            held_translations: 0,
            weakest_translation_cosine: 0.5,
            geometric_information: Some(h),
        }
    }

    /// The held rotation (about x here) takes the reference's angle; the
    /// measured ones stay the registration's.
    #[test]
    fn a_held_rotation_is_turned_to_the_reference() {
        let mut h = Matrix6::identity() * 100.0;
        h[(0, 0)] = 1e-4;
        let reference = Pose::identity().oplus(&Vector6::new(
            3f64.to_radians(),
            1f64.to_radians(),
            0.0,
            0.0,
            0.0,
            0.02,
        ));
        let moved = held_at(held_result(1, h), &reference);
        let eps = moved.t_target_sensor.ominus(&Pose::identity());
        assert!((eps[0].to_degrees() - 3.0).abs() < 1e-6, "{eps:?}");
        assert!(eps[1].abs() < 1e-9 && eps[5].abs() < 1e-9, "{eps:?}");
        // Nothing held: unchanged.
        let kept = held_at(held_result(0, h), &reference);
        assert_eq!(kept.t_target_sensor, Pose::identity());
    }

    /// The held axis is the rotation with the least information once the
    /// translation is marginalised out, even when the raw rotation block
    /// alone would point elsewhere.
    #[test]
    fn weakest_rotation_marginalises_the_translation() {
        let mut h = Matrix6::identity() * 100.0;
        h[(0, 0)] = 1.0; // about x: weak
        let axis = weakest_rotation(&h).expect("an axis");
        assert!((axis.abs() - Vector3::x()).norm() < 1e-9, "{axis}");
        // Rotation about y strongly coupled to translation along z: its
        // Schur complement 100 − 99.9²/100 ≈ 0.2 is the weakest.
        let mut h = Matrix6::identity() * 100.0;
        h[(0, 0)] = 50.0;
        h[(1, 5)] = 99.9;
        h[(5, 1)] = 99.9;
        let axis = weakest_rotation(&h).expect("an axis");
        assert!((axis.abs() - Vector3::y()).norm() < 1e-9, "{axis}");
        // A singular translation block gives no axis.
        let mut h = Matrix6::identity();
        h[(4, 4)] = 0.0;
        assert!(weakest_rotation(&h).is_none());
    }
}
