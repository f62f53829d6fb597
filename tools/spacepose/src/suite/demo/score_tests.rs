//! Tests of the demo's scorer: symmetric equivalents scored with d_sym,
//! and frames scored in any arrival order.

use super::*;
use nalgebra::Vector3;
use spacepose_geometry::{Euler321, Pose};

fn pair(seq: u64, err_deg: f64) -> (PoseEstimate, TruthMsg) {
    let truth_pose = Pose::new(
        Euler321::from_degrees(10.0, 0.0, 0.0).to_rotation(),
        Vector3::new(0.0, 0.0, 15.0),
    );
    let mut t = TruthMsg::new();
    t.sequence = seq;
    t.set_pose(&truth_pose);
    let mut p = PoseEstimate::new();
    p.sequence = seq;
    p.set_pose(&Pose::new(
        Euler321::from_degrees(10.0 + err_deg, 0.0, 0.0).to_rotation(),
        Vector3::new(0.0, 0.02, 15.0),
    ));
    p.total_ms = 5.0;
    p.cloud_published_ns = 1_000_000_000;
    p.published_ns = 1_006_000_000;
    (p, t)
}

#[test]
fn a_symmetric_equivalent_pose_is_scored_with_d_sym() {
    // deos-like group {I, Rx(±120°)}: an estimate off by one group element
    // (plus 1° about z) scores 1° with the group and ~120° without.
    let rx = |deg: f64| Rotation3::from_axis_angle(&Vector3::x_axis(), deg.to_radians());
    let group = vec![Rotation3::identity(), rx(120.0), rx(-120.0)];
    let (mut p, t) = pair(0, 1.0);
    let r_true = t.pose().unwrap().rotation;
    let r_est = Euler321::from_degrees(11.0, 0.0, 0.0).to_rotation() * rx(120.0);
    assert!(
        (so3::distance(
            &r_true,
            &Euler321::from_degrees(10.0, 0.0, 0.0).to_rotation()
        ))
        .abs()
            < 1e-9
    );
    p.set_pose(&Pose::new(r_est, Vector3::new(0.0, 0.02, 15.0)));
    let with = score(&p, &t, None, &group).unwrap();
    let without = score(&p, &t, None, &[]).unwrap();
    assert!(
        (with.ang_err_deg - 1.0).abs() < 1e-6,
        "{}",
        with.ang_err_deg
    );
    assert!(without.ang_err_deg > 100.0, "{}", without.ang_err_deg);
    let mut s = Scorer::with_symmetries(group);
    s.on_pose(p);
    assert!((s.on_truth(t)[0].ang_err_deg - 1.0).abs() < 1e-6);
}

#[test]
fn frames_are_scored_in_any_arrival_order() {
    let mut s = Scorer::default();
    let (p0, t0) = pair(0, 2.0);
    let (p1, t1) = pair(1, 1.0);
    assert!(s.on_pose(p0).is_empty());
    s.on_raw_cloud(0, 999_000_000);
    let f = s.on_truth(t0);
    assert_eq!(f.len(), 1);
    assert!((f[0].ang_err_deg - 2.0).abs() < 1e-9);
    assert!((f[0].pos_err_cm - 2.0).abs() < 1e-9);
    assert!((f[0].latency_ms - 7.0).abs() < 1e-9);
    assert!((f[0].overhead_ms - 2.0).abs() < 1e-9);
    assert!(s.on_truth(t1).is_empty());
    assert_eq!(s.on_pose(p1).len(), 1);
    assert!(s.on_pose(p1).is_empty());
    assert_eq!(s.duplicate_poses, 1);
    let sum = Summary::new("x", &s, 3, 1);
    assert_eq!((sum.poses_published, sum.missed_poses), (2, 1));
    assert!((sum.ang_err_deg.max - 2.0).abs() < 1e-9);
    assert!((sum.ang_err_deg_converged.max - 1.0).abs() < 1e-9);
    assert!(sum.latency_ms.median.is_finite());
}
