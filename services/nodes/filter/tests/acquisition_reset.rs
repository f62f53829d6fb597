//! The filter service restarts from every accepted acquisition (the init
//! service's reacquisition after a loss, issue 5) and ignores rejected ones.
#![allow(clippy::unwrap_used)] // test helpers

use nalgebra::Vector3;
use spacepose_filter_node::{FilterNode, FilterServiceConfig};
use spacepose_geometry::{Pose, so3};
use spacepose_messages::AcquisitionResult;

fn acquisition(t: f64, pose: &Pose, success: u8) -> AcquisitionResult {
    let mut a = AcquisitionResult::new();
    a.method = 1;
    a.success = success;
    a.t_s = t;
    a.set_pose(pose);
    a
}

#[test]
fn an_accepted_acquisition_resets_the_state_and_a_rejected_one_changes_nothing() {
    let first = Pose::new(
        so3::exp(&Vector3::new(0.1, 0.2, 0.3)),
        Vector3::new(0.2, -0.1, 15.0),
    );
    let later = Pose::new(
        so3::exp(&Vector3::new(-1.0, 0.4, 2.0)),
        Vector3::new(-0.3, 0.5, 14.0),
    );
    let mut node = FilterNode::from_config(&FilterServiceConfig::default()).unwrap();
    assert!(node.on_acquisition(&acquisition(1.0, &first, 1)).unwrap());
    let before = node.filter_state();
    assert_eq!((before.initialized, before.t_s), (1, 1.0));

    // A rejected result (f_CONV > f_MAX) carries no usable pose.
    assert!(!node.on_acquisition(&acquisition(9.0, &later, 0)).unwrap());
    assert_eq!(node.filter_state(), before);

    // The reacquisition after a loss: the state restarts at its time and
    // pose, with zero rates (seed 000 §5.2).
    assert!(node.on_acquisition(&acquisition(12.0, &later, 1)).unwrap());
    let s = node.filter_state();
    assert_eq!(s.t_s, 12.0);
    assert_eq!(s.v_sensor, [0.0; 3]);
    assert_eq!(s.w_target, [0.0; 3]);
    assert!(s.pose().unwrap().error_to(&later).0 < 1e-9);
    assert!((s.pose().unwrap().translation - later.translation).norm() < 1e-9);
}
