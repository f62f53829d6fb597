//! A restarted filter service resumes: from a fresh snapshot of its
//! predecessor's state, else from the first tracking estimate it selects.

use crate::config::FilterServiceConfig;
use crate::fusion::EstimateOutcome;
use crate::node::FilterNode;
use crate::snapshot::{load_snapshot, save_snapshot};
use nalgebra::Vector3;
use spacepose_geometry::{Pose, so3};
use spacepose_messages::{AcquisitionResult, PoseEstimate, WireStatus};
use spacepose_runtime::ServiceConfig;
use std::time::Duration;

/// 0.2 rad/s about the target's z axis, approaching at 0.1 m/s.
fn pose_at(t: f64) -> Pose {
    Pose::new(
        so3::exp(&Vector3::new(0.0, 0.0, 0.2 * t)),
        Vector3::new(0.1, 0.0, 20.0 - 0.1 * t),
    )
}

fn estimate(seq: u64, status: WireStatus) -> PoseEstimate {
    let mut e = PoseEstimate::new();
    e.sequence = seq;
    e.t_s = seq as f64;
    e.status = status as u8;
    e.set_pose(&pose_at(seq as f64));
    e
}

fn fuse(node: &mut FilterNode, e: &PoseEstimate) -> EstimateOutcome {
    let (_, fusions) = node.on_estimate(e, 0).unwrap();
    fusions.into_iter().next().unwrap().outcome.unwrap()
}

/// A node that followed frames 1..=n after an acquisition at 0.
fn running_node(n: u64) -> FilterNode {
    let mut node = FilterNode::from_config(&FilterServiceConfig::default()).unwrap();
    let mut a = AcquisitionResult::new();
    a.success = 1;
    a.set_pose(&pose_at(0.0));
    node.on_acquisition(&a).unwrap();
    for k in 1..=n {
        // The first registration after the acquisition restarts the filter.
        let expected = if k == 1 {
            EstimateOutcome::Reinitialized
        } else {
            EstimateOutcome::Fused
        };
        assert_eq!(
            fuse(&mut node, &estimate(k, WireStatus::Tracking)),
            expected
        );
    }
    node
}

#[test]
fn a_restarted_filter_resumes_from_a_fresh_snapshot_with_its_rates() {
    let old = running_node(8);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("filter.filterstate");
    save_snapshot(&path, &old.filter_state()).unwrap();

    let mut new = FilterNode::from_config(&FilterServiceConfig::default()).unwrap();
    let snap = load_snapshot(&path, Duration::from_secs(10))
        .unwrap()
        .unwrap();
    assert!(new.restore(&snap).unwrap());
    let (a, b) = (old.filter_state(), new.filter_state());
    assert_eq!((b.initialized, b.t_s, b.w_target), (1, a.t_s, a.w_target));
    assert!(b.sequence > a.sequence, "the update counter moves on");
    assert!((b.w_target[2] - 0.2).abs() < 0.05, "learnt ω kept: {b:?}");
    // Frame 9 (the predecessor died after frame 8) is fused at once.
    assert_eq!(
        fuse(&mut new, &estimate(9, WireStatus::Tracking)),
        EstimateOutcome::Fused
    );
    // An uninitialised state restores nothing.
    let mut blank = FilterNode::from_config(&FilterServiceConfig::default()).unwrap();
    assert!(!blank.restore(&blank.filter_state()).unwrap());
}

#[test]
fn without_a_snapshot_the_first_tracking_estimate_initialises_it() {
    let mut node = FilterNode::from_config(&FilterServiceConfig::default()).unwrap();
    // Degraded or lost estimates do not.
    assert_eq!(
        fuse(&mut node, &estimate(3, WireStatus::Degraded)),
        EstimateOutcome::NotTracking(WireStatus::Degraded)
    );
    assert_eq!(node.filter_state().initialized, 0);
    let e = estimate(4, WireStatus::Tracking);
    let outcome = fuse(&mut node, &e);
    assert_eq!(outcome, EstimateOutcome::InitializedFromEstimate);
    assert!(outcome.changed_state());
    let s = node.filter_state();
    assert_eq!((s.initialized, s.t_s), (1, 4.0));
    assert_eq!((s.v_sensor, s.w_target), ([0.0; 3], [0.0; 3]));
    assert_eq!(s.p_sensor_target, e.p_sensor_target);
    // Wide: the configured initial attitude sigma, not a tracker's.
    let sigma = FilterServiceConfig::default()
        .filter
        .initial_sigma_rot_deg
        .to_radians();
    assert!((s.attitude_covariance[0][0] - sigma * sigma).abs() < 1e-12);
    // Then it fuses and learns the rate again.
    for k in 5..12 {
        assert_eq!(
            fuse(&mut node, &estimate(k, WireStatus::Tracking)),
            EstimateOutcome::Fused
        );
    }
    assert!((node.filter_state().w_target[2] - 0.2).abs() < 0.05);
}

#[test]
fn initialising_from_tracking_can_be_turned_off() {
    let config = FilterServiceConfig {
        init_from_tracking: false,
        ..FilterServiceConfig::default()
    };
    let mut node = FilterNode::from_config(&config).unwrap();
    assert_eq!(
        fuse(&mut node, &estimate(4, WireStatus::Tracking)),
        EstimateOutcome::NotInitialized
    );
    let bad = FilterServiceConfig {
        snapshot_max_age_s: f64::NAN,
        ..FilterServiceConfig::default()
    };
    assert!(bad.validate().is_err());
}
