use super::nearest_memo::{MemoCounts, NearestMemo};
use super::register::register_icp_counted;
use super::*;
use crate::error::RegistrationError;
use crate::params::{CellLookup, IcpParams};
use crate::test_support::{frame, perturb, rng, target, true_t_sensor_target};
use nalgebra::Vector3;
use rand::RngExt;
use spacepose_geometry::{Point, Pose};
use std::sync::OnceLock;

fn model() -> &'static IcpModel {
    static M: OnceLock<IcpModel> = OnceLock::new();
    M.get_or_init(|| IcpModel::new(&target().model()).unwrap())
}

#[test]
fn converges_from_offsets_and_reports_a_small_f_conv() {
    let truth = true_t_sensor_target().inverse();
    let mut rng = rng(21);
    // Point-to-point ICP converges linearly (slowly along the faces): from
    // a few degrees it needs more than Table 1's 40 iterations here.
    let params = IcpParams {
        max_iterations: 300,
        ..Default::default()
    };
    for &(deg, dist) in &[
        (0.0, 0.0),
        (1.0, 0.01),
        (3.0, 0.03),
        (2.0, 0.05),
        (5.0, 0.0),
    ] {
        let initial = perturb(&truth, f64::to_radians(deg), dist, &mut rng);
        let reg = register_icp(model(), frame(), &initial, &params).unwrap();
        let (ang, d) = reg.t_target_sensor.error_to(&truth);
        let f_conv = reg.f_conv_m2.unwrap();
        println!(
            "ICP from {deg}° {dist} m: {:.4}° {:.3} mm, {} it (converged {}), f_CONV {:.2} mm²",
            ang.to_degrees(),
            d * 1e3,
            reg.iterations,
            reg.converged,
            f_conv * 1e6
        );
        // Point-to-point ICP has its own optimum a few millimetres off on this
        // fixture: voxel centroids at convex edges lie inside the solid, up
        // to 1 cm from any model point, and pull the cloud.
        assert!(reg.converged);
        assert!(
            ang.to_degrees() < 0.1 && d < 0.01,
            "{deg}° {dist} m: {}° {d} m",
            ang.to_degrees()
        );
        // Aligned: millimetres² (the model is sampled every centimetre).
        assert!(f_conv < 2e-5, "{f_conv}");
        assert!(reg.information.cholesky().is_some());
        assert!(reg.inlier_fraction() > 0.95);
    }
}

#[test]
fn f_conv_is_large_when_started_far_off() {
    let truth = true_t_sensor_target().inverse();
    let initial = perturb(&truth, 60f64.to_radians(), 0.3, &mut rng(22));
    let reg = register_icp(model(), frame(), &initial, &IcpParams::default()).unwrap();
    let f_conv = reg.f_conv_m2.unwrap();
    println!(
        "ICP from 60° 0.3 m: f_CONV {:.1} cm², {} it",
        f_conv * 1e4,
        reg.iterations
    );
    // More than 10 cm² (seed 002 §4.5 failure range).
    assert!(f_conv > 1e-3, "{f_conv}");
}

#[test]
fn bad_input_is_an_error_value() {
    let truth = true_t_sensor_target().inverse();
    let p = IcpParams::default();
    assert!(matches!(
        IcpModel::new(&[]),
        Err(RegistrationError::InvalidModel(_))
    ));
    let nan_model = vec![Vector3::new(f64::NAN, 0.0, 0.0); 5];
    assert!(matches!(
        IcpModel::new(&nan_model),
        Err(RegistrationError::InvalidModel(_))
    ));
    assert!(matches!(
        register_icp(model(), &[], &truth, &p),
        Err(RegistrationError::EmptyCloud)
    ));
    let nan = vec![Point::new(0.0, f32::NAN, 1.0, 0.0, 0.0); 4];
    assert!(matches!(
        register_icp(model(), &nan, &truth, &p),
        Err(RegistrationError::AllPointsNonFinite { count: 4 })
    ));
    let far = Pose::new(
        truth.rotation,
        truth.translation + Vector3::new(0.0, 0.0, 30.0),
    );
    assert!(matches!(
        register_icp(model(), frame(), &far, &p),
        Err(RegistrationError::NoCorrespondences { iteration: 0, .. })
    ));
    let bad = IcpParams {
        max_distance_m: -0.1,
        ..p
    };
    assert!(matches!(
        register_icp(model(), frame(), &truth, &bad),
        Err(RegistrationError::InvalidParameter { .. })
    ));
    assert!(matches!(
        register_icp(model(), &frame()[..2], &truth, &p),
        Err(RegistrationError::DegenerateSystem { .. })
    ));
}

/// The grid answers exactly what the kd-tree answers, for queries spread
/// up to 13 cm around the model (beyond the 10 cm the grid serves) and for
/// the frame at offset poses, at two voxel sizes.
#[test]
fn grid_lookup_is_exact_against_the_kd_tree() {
    let points = target().model();
    let mut rng = rng(31);
    let mut queries: Vec<Vector3<f64>> = (0..40_000)
        .map(|_| {
            let base = points[rng.random_range(0..points.len())];
            let dir = Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            base + dir * rng.random_range(0.0..0.13)
        })
        .collect();
    let truth = true_t_sensor_target().inverse();
    for k in 0..4 {
        let t = perturb(
            &truth,
            f64::to_radians(2.0 * k as f64),
            0.02 * k as f64,
            &mut rng,
        );
        queries.extend(frame().iter().map(|p| t.transform(&p.position())));
    }
    for resolution in [0.03, 0.047] {
        let m = IcpModel::with_grid(&points, 0.10, resolution).unwrap();
        let stats = m.lookup_stats();
        println!("{stats:?}");
        assert!(stats.non_empty_voxels > 0);
        let (mut within, mut beyond) = (0, 0);
        for max_distance in [0.10, 0.05] {
            let max2: f64 = max_distance * max_distance;
            for q in &queries {
                let (kd_point, kd_d2) = m.nearest(q);
                match m.nearest_within(q, max_distance, CellLookup::Grid, false) {
                    Some((p, d2)) => {
                        assert!(kd_d2 <= max2, "{q:?}: grid {d2}, kd-tree {kd_d2}");
                        assert!((d2 - kd_d2).abs() <= 1e-15, "{q:?}: {d2} vs {kd_d2}");
                        assert!(((p - q).norm_squared() - d2).abs() <= 1e-15);
                        within += 1;
                    }
                    None => {
                        assert!(kd_d2 > max2, "{q:?}: kd-tree {kd_d2} at {kd_point:?}");
                        beyond += 1;
                    }
                }
                let (_, any_d2) = m.nearest_any(q, CellLookup::Grid, false);
                assert!((any_d2 - kd_d2).abs() <= 1e-15);
            }
        }
        println!("resolution {resolution}: {within} within, {beyond} beyond");
        assert!(within > 0 && beyond > 0);
    }
}

/// A wide stage through the far lookup, then the exact narrow stage, ends
/// where exact searches end; the far lookup is used only from
/// `far_lookup_from_m` on.
#[test]
fn far_lookup_wide_stage_then_exact_stage_matches_exact_searches() {
    let far_model = IcpModel::new(&target().model())
        .unwrap()
        .with_far_lookup(1.0, 0.05)
        .unwrap();
    let stats = far_model.far_lookup_stats();
    assert_eq!(stats.len(), 1);
    assert!(stats[0].voxels > 0 && stats[0].resolution_m >= 0.05);
    let truth = true_t_sensor_target().inverse();
    let initial = perturb(&truth, 8f64.to_radians(), 0.15, &mut rng(23));
    let wide = IcpParams {
        max_distance_m: 0.5,
        max_iterations: 60,
        termination_increment: 1e-5,
        far_lookup_from_m: Some(0.3),
        ..Default::default()
    };
    let narrow = IcpParams {
        max_iterations: 300,
        far_lookup_from_m: Some(0.3),
        ..Default::default()
    };
    let run = |m: &IcpModel| {
        let w = register_icp(m, frame(), &initial, &wide).unwrap();
        register_icp(m, frame(), &w.t_target_sensor, &narrow).unwrap()
    };
    let (approx, exact) = (run(&far_model), run(model()));
    let (ang, d) = approx.t_target_sensor.error_to(&exact.t_target_sensor);
    assert!(
        ang.to_degrees() < 0.05 && d < 0.002,
        "{}° {d} m",
        ang.to_degrees()
    );
    // The narrow stage (10 cm < 0.3 m) stayed exact: same f_CONV.
    let (fa, fe) = (approx.f_conv_m2.unwrap(), exact.f_conv_m2.unwrap());
    assert!((fa - fe).abs() <= 0.05 * fe + 1e-9, "{fa} vs {fe}");
    // Invalid settings are refused.
    assert!(
        IcpParams {
            far_lookup_from_m: Some(f64::NAN),
            ..Default::default()
        }
        .validate()
        .is_err()
    );
    assert!(
        IcpModel::new(&target().model())
            .unwrap()
            .with_far_lookup(-1.0, 0.1)
            .is_err()
    );
}

/// A query outside the far lookup has no model point within its margin:
/// a search limited to the margin finds none without the kd-tree, and a
/// wider one still gets the exact nearest point.
#[test]
fn far_lookup_answers_none_beyond_its_margin() {
    let far_model = IcpModel::new(&target().model())
        .unwrap()
        .with_far_lookup(1.0, 0.1)
        .unwrap();
    let (lo, hi) = target().model().iter().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    let q = Vector3::new(hi.x + 3.0, 0.5 * (lo.y + hi.y), 0.5 * (lo.z + hi.z));
    assert!(
        far_model
            .nearest_within(&q, 1.0, CellLookup::Grid, true)
            .is_none()
    );
    let (p, d2) = far_model.nearest(&q);
    assert!(d2 > 4.0, "{d2}");
    let wide = far_model.nearest_within(&q, 10.0, CellLookup::Grid, true);
    assert_eq!(wide, Some((p, d2)));
}

/// The memoised grid lookup answers exactly as a scan of the voxel while
/// queries drift by steps from 10 µm to 2 cm (the scale of ICP's late and
/// early increments), and reuses its memo on the small steps.
#[test]
fn memoised_lookup_matches_a_scan_along_drifting_queries() {
    let m = model();
    let points = target().model();
    let mut rng = rng(41);
    let max2 = 0.1f64 * 0.1;
    let mut counts = MemoCounts::default();
    let mut answers = 0;
    for walk in 0..3000 {
        let base = points[rng.random_range(0..points.len())];
        let mut q = base + Vector3::new(0.05, -0.03, 0.04) * rng.random_range(-1.5..1.5);
        let step = [1e-5, 1e-4, 1e-3, 2e-2][walk % 4];
        let mut memo = NearestMemo::default();
        for _ in 0..30 {
            let memoised = m.grid.nearest_within_memo(&q, max2, &mut memo, &mut counts);
            let scanned = m.grid.nearest_within(&q, max2);
            assert_eq!(memoised, scanned, "{q:?} (step {step} m)");
            answers += usize::from(scanned.is_some());
            let dir = Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            q += dir * step;
        }
    }
    println!("{counts:?}, {answers} answers within 10 cm of 90000 lookups");
    assert!(answers > 30_000);
    assert!(
        counts.reused > 30_000 && counts.scans > 10_000,
        "{counts:?}"
    );
}

/// ICP through the memoised grid ends exactly where ICP through the
/// kd-tree ends, and late iterations mostly reuse the memos.
#[test]
fn memoised_icp_matches_kd_tree_icp() {
    let truth = true_t_sensor_target().inverse();
    let initial = perturb(&truth, 3f64.to_radians(), 0.03, &mut rng(42));
    let grid = IcpParams::default();
    let kd = IcpParams {
        lookup: CellLookup::KdTree,
        ..grid
    };
    let (with_memo, counts) = register_icp_counted(model(), frame(), &initial, &grid);
    let (with_memo, (by_tree, tree_counts)) = (
        with_memo.unwrap(),
        register_icp_counted(model(), frame(), &initial, &kd),
    );
    let by_tree = by_tree.unwrap();
    let (ang, d) = with_memo.t_target_sensor.error_to(&by_tree.t_target_sensor);
    println!(
        "{counts:?} over {} iterations of {} points; {ang:e} rad, {d:e} m apart",
        with_memo.iterations,
        frame().len()
    );
    assert!(ang < 1e-9 && d < 1e-9);
    assert_eq!(with_memo.iterations, by_tree.iterations);
    assert_eq!(with_memo.inliers, by_tree.inliers);
    assert_eq!(tree_counts, MemoCounts::default());
    assert!(counts.reused > counts.scans, "{counts:?}");
}
