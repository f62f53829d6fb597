//! The verification of a hand-over through the node (`crate::verify`),
//! with scripted methods so that the chain's answers are known.

use super::*;

/// A method whose answers are scripted per call: the `k`-th call answers
/// `script[k]` (the last one after that): a pose, accepted or not.
struct Scripted {
    method: AcquisitionMethod,
    script: Vec<Option<Pose>>,
    calls: std::sync::atomic::AtomicUsize,
}

impl PoseAcquirer for Scripted {
    fn method(&self) -> AcquisitionMethod {
        self.method
    }

    fn acquire(&self, _: &[Point]) -> Result<MethodOutput, InitError> {
        let k = self.calls.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        let answer = self.script[k.min(self.script.len() - 1)];
        Ok(MethodOutput {
            t_sensor_target: answer.unwrap_or_else(Pose::identity),
            f_conv_m2: 1e-3,
            accepted: answer.is_some(),
            detail: String::new(),
        })
    }
}

/// The tracker's `tracking` estimate of `sequence` at `pose`, started
/// after the last result went out.
fn tracking_at(sequence: u64, pose: &Pose) -> PoseEstimate {
    let mut e = tracker(
        sequence,
        WireStatus::Tracking,
        realtime_ns() + 1_000_000_000,
    );
    e.set_pose(pose);
    e
}

/// The tracker's `unconfirmed` estimate of `sequence` at `pose`, its track
/// awaiting the confirmation of the acquisition of frame `acquired`.
fn unconfirmed_at(sequence: u64, pose: &Pose, acquired: u64) -> PoseEstimate {
    let mut e = tracking_at(sequence, pose);
    e.status = WireStatus::Unconfirmed as u8;
    e.acquisition_sequence = acquired;
    e
}

/// The tracker's `estimate` of each frame, then the frame: each one is
/// looked at (a verification runs after it).
fn looked_at(h: &mut Harness, frames: [u64; 2], estimate: impl Fn(u64) -> PoseEstimate) {
    let points = vec![Point::new(0.0, 0.0, 15.0, 1.0, 0.0); 5];
    for k in frames {
        h.estimate(estimate(k));
        assert!(h.cloud(k, &points).is_empty());
        assert!(h.node.busy(), "frame {k} is verified");
    }
}

/// A node whose chain is the CNN then template matching, each scripted,
/// verifying with the defaults on deos.
fn verifying_node(cnn: Vec<Option<Pose>>, tm: Vec<Option<Pose>>) -> Harness {
    let scripted = |method, script| -> Box<dyn PoseAcquirer> {
        Box::new(Scripted {
            method,
            script,
            calls: 0.into(),
        })
    };
    let chain = MethodChain::new(
        vec![
            scripted(AcquisitionMethod::Cnn, cnn),
            scripted(AcquisitionMethod::TemplateMatching, tm),
        ],
        3,
    )
    .unwrap();
    let deos = Target::builtin("deos").unwrap();
    let verifier = Verifier::new(
        crate::verify::VerifyConfig::default(),
        deos.symmetries().to_vec(),
        deos.bounding_radius(),
    );
    let node = InitNode::with_chain(chain, InitConfig::default(), Name::new("init").unwrap());
    Harness::new(node.unwrap().with_verifier(verifier))
}

fn truth() -> Pose {
    use nalgebra::{Rotation3, Vector3};
    Pose::new(
        Rotation3::from_euler_angles(0.3, 0.2, 0.1),
        Vector3::new(0.0, 0.0, 15.0),
    )
}

/// Template matching (the fallback) hands over a pose on deos' 60° twin;
/// the CNN, rejected on the first frame, finds the truth on the next two:
/// the verification replaces the track with the CNN's pose, published as
/// an acquisition; the new track (the CNN's) is verified by agreements.
#[test]
fn a_fallback_track_the_cnn_contradicts_twice_is_replaced() {
    use nalgebra::{Rotation3, Vector3};
    let truth = truth();
    let twin = Pose::new(
        truth.rotation * Rotation3::from_axis_angle(&Vector3::x_axis(), 60f64.to_radians()),
        truth.translation,
    );
    let mut h = verifying_node(vec![None, Some(truth)], vec![Some(twin)]);
    let points = vec![Point::new(0.0, 0.0, 15.0, 1.0, 0.0); 5];

    assert!(h.cloud(0, &points).is_empty());
    h.estimate(tracker(0, WireStatus::Lost, NOW_NS));
    let first = h.finished();
    assert_eq!(first.method, AcquisitionMethod::TemplateMatching as u8);
    assert!(
        first.pending(),
        "a fallback's track awaits its verification"
    );
    // Frame 1: the track (on the twin) is verified; the CNN contradicts it.
    assert!(h.cloud(1, &points).is_empty());
    h.estimate(tracking_at(1, &twin));
    assert!(h.node.busy(), "a verification runs");
    // Frame 2 arrives while it runs; its verification follows.
    assert!(h.cloud(2, &points).is_empty());
    h.estimate(tracking_at(2, &twin));
    let replaced = h.finished();
    assert_eq!(replaced.sequence, 2);
    assert_eq!(replaced.method, AcquisitionMethod::Cnn as u8);
    assert!(
        replaced.pending(),
        "the CNN's track awaits its confirmation"
    );
    let (deg, m) = replaced.pose().unwrap().error_to(&truth);
    assert!(deg < 1e-9 && m < 1e-9, "{deg} deg, {m} m");
    assert!(matches!(h.node.phase(), Phase::HandedOver { frame: 2, .. }));
    // The CNN's own track: two agreements confirm it.
    looked_at(&mut h, [3, 4], |k| tracking_at(k, &truth));
    let confirms = h.finished();
    assert_eq!(confirms.confirms(), Some(2), "{confirms:?}");
    assert_eq!(h.counters.frames_out, 3, "verifications are not published");
}

/// Template matching hands over the true pose; the CNN keeps rejecting
/// its poses, and template matching finds the track's pose again on the
/// next two frames (published `unconfirmed` by the tracker): the second
/// agreement sends one record that confirms the acquisition of frame 0.
#[test]
fn a_fallback_track_two_verifications_agree_with_is_confirmed_once() {
    let truth = truth();
    let mut h = verifying_node(vec![None], vec![Some(truth)]);
    let points = vec![Point::new(0.0, 0.0, 15.0, 1.0, 0.0); 5];
    assert!(h.cloud(0, &points).is_empty());
    h.estimate(tracker(0, WireStatus::Lost, NOW_NS));
    let first = h.finished();
    assert!(first.pending());
    looked_at(&mut h, [1, 2], |k| unconfirmed_at(k, &truth, 0));
    let confirms = h.finished();
    assert_eq!(confirms.confirms(), Some(0), "{confirms:?}");
    assert_eq!(
        (confirms.method, confirms.success, confirms.q_sensor_target),
        (first.method, 1, first.q_sensor_target)
    );
    // Confirmed: no verification after that, nothing more published.
    h.estimate(tracking_at(3, &truth));
    assert!(h.cloud(3, &points).is_empty());
    assert!(!h.node.busy());
    assert_eq!(h.counters.frames_out, 2);
}

/// A restarted init (it published nothing) hears a track `unconfirmed`
/// since the acquisition of frame 3: it verifies it and confirms frame 3's
/// acquisition, once.
#[test]
fn a_restarted_init_takes_over_the_verification_of_an_unconfirmed_track() {
    let truth = truth();
    let mut h = verifying_node(vec![Some(truth)], vec![None]);
    let points = vec![Point::new(0.0, 0.0, 15.0, 1.0, 0.0); 5];
    looked_at(&mut h, [5, 6], |k| unconfirmed_at(k, &truth, 3));
    let confirms = h.finished();
    assert_eq!(confirms.confirms(), Some(3), "{confirms:?}");
    assert_eq!(confirms.method, AcquisitionMethod::Cnn as u8);
    // The tracker's next frame, computed before the confirmation reached
    // it, is still `unconfirmed`: nothing is verified again.
    h.estimate(unconfirmed_at(7, &truth, 3));
    assert!(h.cloud(7, &points).is_empty());
    assert!(!h.node.busy());
    assert_eq!(h.counters.frames_out, 1);
}
