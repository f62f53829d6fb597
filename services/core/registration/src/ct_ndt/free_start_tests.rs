use super::*;
use crate::ct_ndt::interpolation::{Interpolation, exp_coefficients};
use crate::ct_ndt::joint::{Matrix12, Vector12};
use crate::ct_ndt::{ct_point_jacobian, interpolate, register_ct_ndt};
use crate::test_support::{map, perturb, rng, target, true_t_sensor_target};
use nalgebra::Matrix3x6;
use nalgebra::{Matrix3, Matrix6, SMatrix, Vector3, Vector6};
use rand::RngExt;
use spacepose_geometry::so3;

/// The start-pose Jacobian is Eq. (15) with the ends swapped, and equals
/// `J^total − J^e` as `linearise` computes it.
#[test]
fn start_pose_jacobian_agrees_with_finite_differences() {
    let mut rng = rng(21);
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for _ in 0..50 {
        let start = perturb(&true_t_sensor_target().inverse(), 0.5, 0.3, &mut rng);
        let end = perturb(&start, 0.3, 0.1, &mut rng);
        let u = rng.random_range(0.0..1.0);
        let z = Vector3::new(
            rng.random_range(-3.0..3.0),
            rng.random_range(-3.0..3.0),
            rng.random_range(2.0..9.0),
        );
        let swapped = ct_point_jacobian(&end, &start, 1.0 - u, &z);
        // The form `linearise` uses: J^total − J^e from the end's blocks.
        let forward = Interpolation::new(&start, &end);
        let c_u = exp_coefficients(forward.phi.norm_squared() * u * u);
        let le = forward.apply(&(start.rotation * z), u);
        let (j_r, j_t) = forward.start_jacobian(&le, u, c_u);
        let mut from_end = Matrix3x6::zeros();
        from_end.fixed_view_mut::<3, 3>(0, 0).copy_from(&j_r);
        from_end.fixed_view_mut::<3, 3>(0, 3).copy_from(&j_t);
        let f = |d: &Vector6<f64>| interpolate(&start.oplus(d), &end, u).transform(&z);
        for j in 0..6 {
            let mut d = Vector6::zeros();
            d[j] = h;
            let fd = (f(&d) - f(&(-d))) / (2.0 * h);
            for analytic in [&swapped, &from_end] {
                let col = analytic.column(j);
                worst = worst.max((fd - col).norm() / col.norm().max(1e-3));
            }
        }
    }
    assert!(worst < 1e-6, "worst relative error {worst}");
}

/// `∂(T^s ⊖ T₀)/∂δ^s = blockdiag(J_l⁻¹, I)`, as used by the prior term.
#[test]
fn prior_jacobian_agrees_with_finite_differences() {
    let mut rng = rng(22);
    let t0 = true_t_sensor_target().inverse();
    let start = perturb(&t0, 0.2, 0.1, &mut rng);
    let prior = StartPrior {
        t_target_sensor: t0,
        information: Matrix6::identity(),
    };
    let mut joint = Joint::new();
    joint.add_prior(&start, &prior);
    // With Ω = I the prior adds JᵀJ and Jᵀe; recover J from the gradient of
    // ½|e|² by finite differences and compare Jᵀe.
    let cost = |d: &Vector6<f64>| 0.5 * start.oplus(d).ominus(&t0).norm_squared();
    let h = 1e-6;
    for j in 0..6 {
        let mut d = Vector6::zeros();
        d[j] = h;
        let fd = (cost(&d) - cost(&(-d))) / (2.0 * h);
        assert!(
            (fd - joint.g[j]).abs() < 1e-7,
            "column {j}: {fd} vs {}",
            joint.g[j]
        );
    }
}

/// A blurred scan whose true start pose is `start`.
fn blurred_scan() -> (Vec<Point>, Pose, Pose, ScanTimes) {
    let start = true_t_sensor_target().inverse();
    let end = perturb(&start, 6f64.to_radians(), 0.04, &mut rng(13));
    let scan = ScanTimes {
        start_s: 10.0,
        end_s: 11.0,
    };
    let frame = target().blurred_frame(&start, &end, scan.start_s, scan.end_s, 0.02);
    (frame, start, end, scan)
}

#[test]
fn a_firm_prior_gives_back_eq_14() {
    let (frame, start, end, scan) = blurred_scan();
    // The free start has no coarse phase: neither has Eq. (14) here, so
    // both take the same steps.
    let params = NdtParams {
        coarse_stride: 1,
        ..NdtParams::default()
    };
    let guess = perturb(&end, 2f64.to_radians(), 0.02, &mut rng(14));
    let fixed = register_ct_ndt(map(), &frame, &scan, &start, &guess, &params).unwrap();
    let prior = StartPrior {
        t_target_sensor: start,
        information: Matrix6::identity() * 1e12,
    };
    let free = register_ct_ndt_free_start(map(), &frame, &scan, &prior, &guess, &params).unwrap();
    let (ang, d) = free.end.t_target_sensor.error_to(&fixed.t_target_sensor);
    assert!(ang.to_degrees() < 0.01 && d < 1e-4, "{ang} rad, {d} m");
    assert!(free.start_correction.rotation_rad < 1e-6);
    assert!(free.end.converged);
}

/// The failure mode of Eq. (14): a start pose 1.5° and 5 cm off. Fixed,
/// it drags the end pose; under a loose prior the scan corrects it.
#[test]
fn a_wrong_start_is_corrected_under_a_loose_prior() {
    let (frame, start, end, scan) = blurred_scan();
    let params = NdtParams::default();
    let wrong_start = perturb(&start, 1.5f64.to_radians(), 0.05, &mut rng(15));
    let guess = perturb(&end, 2f64.to_radians(), 0.02, &mut rng(14));
    let fixed = register_ct_ndt(map(), &frame, &scan, &wrong_start, &guess, &params).unwrap();
    // σ = 3° and 10 cm on the start.
    let (s_rot, s_pos) = (3f64.to_radians(), 0.1);
    let information = Matrix6::from_diagonal(&Vector6::new(
        1.0 / (s_rot * s_rot),
        1.0 / (s_rot * s_rot),
        1.0 / (s_rot * s_rot),
        1.0 / (s_pos * s_pos),
        1.0 / (s_pos * s_pos),
        1.0 / (s_pos * s_pos),
    ));
    let prior = StartPrior {
        t_target_sensor: wrong_start,
        information,
    };
    let free = register_ct_ndt_free_start(map(), &frame, &scan, &prior, &guess, &params).unwrap();
    let (fixed_ang, fixed_d) = fixed.t_target_sensor.error_to(&end);
    let (free_ang, free_d) = free.end.t_target_sensor.error_to(&end);
    let (start_ang, start_d) = free.t_target_sensor_start.error_to(&start);
    println!(
        "end error: fixed start {:.3}° {:.1} mm, free start {:.3}° {:.1} mm; \
         start error {:.3}° {:.1} mm ({} it)",
        fixed_ang.to_degrees(),
        fixed_d * 1e3,
        free_ang.to_degrees(),
        free_d * 1e3,
        start_ang.to_degrees(),
        start_d * 1e3,
        free.end.iterations
    );
    assert!(free_ang.to_degrees() < 0.3 && free_d < 0.02);
    assert!(free_ang < fixed_ang / 2.0 && free_d < fixed_d);
    assert!(start_ang.to_degrees() < 0.5 && start_d < 0.02);
    assert!(free.end.information.cholesky().is_some());
    // The marginal information of T^e is below the joint block's.
    assert!(free.end.cost.mean.is_finite());
}

#[test]
fn bad_prior_is_an_error_value() {
    let (frame, start, _, scan) = blurred_scan();
    let mut prior = StartPrior {
        t_target_sensor: start,
        information: Matrix6::identity(),
    };
    prior.information[(2, 2)] = f64::NAN;
    let p = NdtParams::default();
    assert!(matches!(
        register_ct_ndt_free_start(map(), &frame, &scan, &prior, &start, &p),
        Err(RegistrationError::InvalidParameter { .. })
    ));
    prior.information = Matrix6::identity();
    assert!(matches!(
        register_ct_ndt_free_start(map(), &[], &scan, &prior, &start, &p),
        Err(RegistrationError::EmptyCloud)
    ));
}

/// The turn `R^e (R^s)ᵀ` of a CT-NDT result.
fn turn_of(r: &CtRegistration) -> nalgebra::Rotation3<f64> {
    r.end.t_target_sensor.rotation * r.t_target_sensor_start.rotation.inverse()
}

/// A firm prior on the turn over the scan imposes it: at the true turn the
/// result is as good as without it, at a turn 1° off the result turns by
/// that instead, while the loose start prior lets the pose follow the
/// points. Without the rate prior the scan finds the true turn.
#[test]
fn a_firm_rate_prior_imposes_the_turn() {
    let (frame, start, end, scan) = blurred_scan();
    let params = NdtParams::default();
    let guess = perturb(&end, 2f64.to_radians(), 0.02, &mut rng(14));
    let s_rot = 3f64.to_radians();
    let information = Matrix6::from_diagonal(&Vector6::new(
        1.0 / (s_rot * s_rot),
        1.0 / (s_rot * s_rot),
        1.0 / (s_rot * s_rot),
        100.0,
        100.0,
        100.0,
    ));
    let start_prior = StartPrior {
        t_target_sensor: start,
        information,
    };
    let true_turn = end.rotation * start.rotation.inverse();
    let off = so3::exp(&Vector3::new(0.0, 1f64.to_radians(), 0.0));
    let run = |turn: Option<nalgebra::Rotation3<f64>>| {
        let priors = CtPriors {
            start: start_prior,
            rate: turn.map(|turn| RatePrior {
                turn,
                information: Matrix3::identity() * 1e12,
            }),
            displacement: None,
        };
        register_ct_ndt_with_priors(map(), &frame, &scan, &priors, &guess, &params).unwrap()
    };
    let deg = |a: &nalgebra::Rotation3<f64>, b: &nalgebra::Rotation3<f64>| {
        so3::distance(a, b).to_degrees()
    };
    let free = run(None);
    let at_truth = run(Some(true_turn));
    let wrong = run(Some(off * true_turn));
    println!(
        "turn error: free {:.3}°, at truth {:.2e}°, 1° off {:.2e}° from its prior",
        deg(&turn_of(&free), &true_turn),
        deg(&turn_of(&at_truth), &true_turn),
        deg(&turn_of(&wrong), &(off * true_turn))
    );
    assert!(deg(&turn_of(&free), &true_turn) < 0.6);
    assert!(deg(&turn_of(&at_truth), &true_turn) < 1e-3);
    assert!(deg(&turn_of(&wrong), &(off * true_turn)) < 1e-3);
    // The true turn helps the end pose (free: 0.23°, 18 mm).
    let (ang, d) = at_truth.end.t_target_sensor.error_to(&end);
    let (free_ang, free_d) = free.end.t_target_sensor.error_to(&end);
    assert!(ang < free_ang && d < free_d, "{ang} rad, {d} m");
    assert!(ang.to_degrees() < 0.1 && d < 0.015, "{ang} rad, {d} m");
    let (ang, _) = wrong.end.t_target_sensor.error_to(&end);
    assert!(ang.to_degrees() > 0.2, "{} deg", ang.to_degrees());
    // The firm turn adds information: the end pose's marginal grows.
    let trace = |r: &CtRegistration| r.end.information.fixed_view::<3, 3>(0, 0).trace();
    assert!(trace(&at_truth) > trace(&free));
}

/// The target origin in the sensor frame, `-Rᵀ t` of `t_target_sensor`.
fn origin(p: &Pose) -> Vector3<f64> {
    -(p.rotation.inverse() * p.translation)
}

/// With firm priors on the turn and the displacement at their true values,
/// no start prior is needed: the points fix the pose, which lands on the
/// truth (the motion-compensated fit of `deblur`, in the limit).
#[test]
fn firm_motion_priors_need_no_start_prior() {
    let (frame, start, end, scan) = blurred_scan();
    let guess = perturb(&end, 2f64.to_radians(), 0.02, &mut rng(14));
    let priors = CtPriors {
        start: StartPrior {
            t_target_sensor: perturb(&start, 0.1, 0.5, &mut rng(16)),
            information: Matrix6::zeros(),
        },
        rate: Some(RatePrior {
            turn: end.rotation * start.rotation.inverse(),
            information: Matrix3::identity() * 1e12,
        }),
        displacement: Some(DisplacementPrior {
            displacement_m: origin(&end) - origin(&start),
            information: Matrix3::identity() * 1e12,
        }),
    };
    let r =
        register_ct_ndt_with_priors(map(), &frame, &scan, &priors, &guess, &NdtParams::default())
            .unwrap();
    let (ang, d) = r.end.t_target_sensor.error_to(&end);
    let (s_ang, s_d) = r.t_target_sensor_start.error_to(&start);
    println!(
        "end {:.4}° {:.2} mm, start {:.4}° {:.2} mm",
        ang.to_degrees(),
        d * 1e3,
        s_ang.to_degrees(),
        s_d * 1e3
    );
    // NDT's own error on this noisy frame (0.07°, 4.5 mm); the loose start
    // prior alone leaves 0.23° and 18 mm (test above).
    assert!(ang.to_degrees() < 0.1 && d < 0.006, "{ang} rad, {d} m");
    assert!(s_ang.to_degrees() < 0.1 && s_d < 0.006);
    // A displacement prior 3 cm off moves both poses by that instead.
    let mut off = priors;
    if let Some(p) = off.displacement.as_mut() {
        p.displacement_m.x += 0.03;
    }
    let r = register_ct_ndt_with_priors(map(), &frame, &scan, &off, &guess, &NdtParams::default())
        .unwrap();
    let moved = origin(&r.end.t_target_sensor) - origin(&r.t_target_sensor_start);
    assert!((moved - off.displacement.unwrap().displacement_m).norm() < 1e-4);
}

#[test]
fn the_motion_priors_coarse_phase_reaches_the_full_clouds_optimum() {
    // Loose motion priors (0.5° and 1 cm), no start prior, both poses 2° /
    // 2 cm off: with the coarse phase (every fourth point first) and
    // without it, the end poses agree to within the termination's
    // stopping spread (measured: 0.002°, 0.14 mm).
    let (frame, start, end, scan) = blurred_scan();
    let guess = perturb(&end, 2f64.to_radians(), 0.02, &mut rng(21));
    let priors = CtPriors {
        start: StartPrior {
            t_target_sensor: perturb(&start, 2f64.to_radians(), 0.02, &mut rng(22)),
            information: Matrix6::zeros(),
        },
        rate: Some(RatePrior {
            turn: end.rotation * start.rotation.inverse(),
            information: Matrix3::identity() / 0.5f64.to_radians().powi(2),
        }),
        displacement: Some(DisplacementPrior {
            displacement_m: origin(&end) - origin(&start),
            information: Matrix3::identity() / 0.01f64.powi(2),
        }),
    };
    let run = |coarse_stride| {
        let params = NdtParams {
            coarse_stride,
            ..NdtParams::default()
        };
        register_ct_ndt_with_priors(map(), &frame, &scan, &priors, &guess, &params).unwrap()
    };
    let (coarse, full) = (run(4), run(1));
    let (ang, d) = coarse
        .end
        .t_target_sensor
        .error_to(&full.end.t_target_sensor);
    let (c_ang, c_d) = coarse.end.t_target_sensor.error_to(&end);
    println!(
        "coarse vs full: {:.4}° {:.2} mm ({} vs {} it); coarse vs truth {:.4}° {:.2} mm",
        ang.to_degrees(),
        d * 1e3,
        coarse.end.iterations,
        full.end.iterations,
        c_ang.to_degrees(),
        c_d * 1e3
    );
    assert!(coarse.end.converged && full.end.converged);
    assert!(ang.to_degrees() < 0.1 && d < 0.003, "{ang} rad, {d} m");
}

#[test]
fn bad_rate_prior_is_an_error_value() {
    let (frame, start, _, scan) = blurred_scan();
    let priors = CtPriors {
        start: StartPrior {
            t_target_sensor: start,
            information: Matrix6::identity(),
        },
        rate: Some(RatePrior {
            turn: nalgebra::Rotation3::identity(),
            information: Matrix3::identity() * f64::NAN,
        }),
        displacement: None,
    };
    let p = NdtParams::default();
    assert!(matches!(
        register_ct_ndt_with_priors(map(), &frame, &scan, &priors, &start, &p),
        Err(RegistrationError::InvalidParameter { .. })
    ));
}

/// `linearise`'s structured sums equal `Σ JᵀPJ` and `Σ JᵀPr` formed from
/// the dense 3×12 Jacobian `[∂p/∂δ^s, ∂p/∂δ^e]` of every inlier.
#[test]
fn linearise_matches_the_dense_normal_equations() {
    let (frame, start, end, scan) = blurred_scan();
    let params = NdtParams::default();
    let guess_start = perturb(&start, 0.5f64.to_radians(), 0.01, &mut rng(31));
    let guess_end = perturb(&end, 1f64.to_radians(), 0.02, &mut rng(32));
    let points: Vec<(Vector3<f64>, f64)> = frame
        .iter()
        .step_by(7)
        .map(|p| (p.position(), scan.factor(p.t)))
        .collect();
    let joint = linearise(map(), &points, &guess_start, &guess_end, &params);
    let (mut h, mut g) = (Matrix12::zeros(), Vector12::zeros());
    let mut inliers = 0;
    for &(z, u) in &points {
        let p = interpolate(&guess_start, &guess_end, u).transform(&z);
        let Some((k, _)) = map().nearest_cell(&p, params.max_distance_m, params.lookup) else {
            continue;
        };
        let (mean, information) = map().mean_and_information(k);
        let mut j = SMatrix::<f64, 3, 12>::zeros();
        j.fixed_view_mut::<3, 6>(0, 0).copy_from(&ct_point_jacobian(
            &guess_end,
            &guess_start,
            1.0 - u,
            &z,
        ));
        j.fixed_view_mut::<3, 6>(0, 6).copy_from(&ct_point_jacobian(
            &guess_start,
            &guess_end,
            u,
            &z,
        ));
        h += j.transpose() * information * j;
        g += j.transpose() * information * (p - mean);
        inliers += 1;
    }
    assert_eq!(joint.inliers, inliers);
    assert!(inliers > 100, "{inliers}");
    let rel_h = (joint.h - h).norm() / h.norm();
    let rel_g = (joint.g - g).norm() / g.norm();
    assert!(rel_h < 1e-9 && rel_g < 1e-9, "h {rel_h}, g {rel_g}");
}
