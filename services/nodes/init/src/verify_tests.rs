use super::*;
use nalgebra::Vector3;

fn rx(deg: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Vector3::x_axis(), deg.to_radians())
}

/// deos' group (the identity and ±120° about x), and a track acquired by
/// the chain's second method (template matching after the CNN).
fn verifier() -> Verifier {
    let group = vec![Rotation3::identity(), rx(120.0), rx(-120.0)];
    let mut v = Verifier::new(VerifyConfig::default(), group, 1.6);
    v.reset(Some(1), None);
    v
}

/// The truth at frame `k`: turning 10° a frame about a tilted axis.
fn truth(k: u64) -> Pose {
    let w = Vector3::new(0.1, 0.15, 0.05);
    Pose::new(
        Rotation3::from_euler_angles(0.3, -0.2, 0.8) * so3::exp(&(w * k as f64)),
        Vector3::new(0.2, -0.1, 15.0),
    )
}

/// `pose` turned by `r` in its body frame.
fn turned(pose: Pose, r: Rotation3<f64>) -> Pose {
    Pose::new(pose.rotation * r, pose.translation)
}

fn track(v: &mut Verifier, frames: std::ops::Range<u64>, offset: Rotation3<f64>) {
    for k in frames {
        v.on_tracked(TrackedPose {
            sequence: k,
            t_sensor_target: turned(truth(k), offset),
        });
    }
}

#[test]
fn a_correct_track_is_confirmed_then_left_alone() {
    let mut v = verifier();
    track(&mut v, 0..2, Rotation3::identity());
    assert!(v.due(0) && !v.confirmed());
    for k in 0..2 {
        // 3° off, and a symmetric variant: agrees.
        let pose = turned(
            truth(k),
            rx(120.0) * so3::exp(&Vector3::new(0.0, 0.05, 0.0)),
        );
        assert_eq!(
            v.on_result(k, Some((pose, 0))),
            Verdict::Agrees { confirmed: k == 1 }
        );
    }
    assert!(v.confirmed() && !v.due(2) && !v.due(50));
}

#[test]
fn each_frame_once_and_only_what_can_be_compared() {
    let mut v = verifier();
    track(&mut v, 0..1, Rotation3::identity());
    assert!(v.due(0));
    assert_eq!(v.on_result(0, None), Verdict::Unknown);
    assert!(!v.due(0), "a frame is verified once");
    // A frame the tracker did not report as tracking.
    assert_eq!(v.on_result(5, Some((truth(5), 0))), Verdict::Unknown);
    assert!(!v.due(4) && v.due(6));
    // A track of no method of the chain is not verified.
    v.reset(None, None);
    assert!(!v.due(0));
    // A track is verified from the frame after its acquisition's.
    v.reset(Some(1), Some(7));
    assert!(!v.due(7) && v.due(8));
}

#[test]
fn a_track_of_the_first_method_is_confirmed_by_agreements_and_never_replaced() {
    let mut v = verifier();
    v.reset(Some(0), None);
    assert!(v.verifies(0) && v.due(0));
    // Its own method contradicting it twice with one offset: no replacement.
    track(&mut v, 0..4, rx(60.0));
    for k in 0..2 {
        assert_eq!(v.on_result(k, Some((truth(k), 0))), Verdict::Unknown);
    }
    assert!(
        !v.confirmed() && v.due(2),
        "still unconfirmed, still verified"
    );
    // Agreeing twice confirms it.
    for k in 2..4 {
        let verdict = v.on_result(k, Some((turned(truth(k), rx(60.0)), 0)));
        assert_eq!(verdict, Verdict::Agrees { confirmed: k == 3 });
    }
    // Off by configuration: the first method's tracks are trusted.
    let config = VerifyConfig {
        confirm_first_method: false,
        ..VerifyConfig::default()
    };
    let mut v = Verifier::new(config, vec![Rotation3::identity()], 1.6);
    v.reset(Some(0), None);
    assert!(!v.verifies(0) && v.verifies(1) && !v.due(0));
}

#[test]
fn contradictions_of_a_more_trusted_method_with_one_offset_replace_the_track() {
    let mut v = verifier();
    // The track sits on the Rx(60°) twin; the verifications find the truth.
    track(&mut v, 0..3, rx(-60.0));
    match v.on_result(0, Some((truth(0), 0))) {
        Verdict::Contradicts {
            in_a_row: 1,
            off_deg,
        } => assert!((off_deg - 60.0).abs() < 1e-6),
        other => panic!("{other:?}"),
    }
    // The same method as the track's is no evidence against it.
    assert_eq!(v.on_result(1, Some((truth(1), 1))), Verdict::Unknown);
    // The next contradiction has the same offset (up to the symmetries).
    let second = turned(truth(2), rx(120.0));
    match v.on_result(2, Some((second, 0))) {
        Verdict::Replace {
            t_sensor_target,
            off_deg,
        } => {
            assert_eq!(t_sensor_target, second);
            assert!((off_deg - 60.0).abs() < 1e-6);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn contradictions_apart_or_with_other_offsets_or_an_agreement_start_again() {
    let mut v = verifier();
    track(&mut v, 0..12, Rotation3::identity());
    let flip_y = Rotation3::from_axis_angle(&Vector3::y_axis(), std::f64::consts::PI);
    let flip_z = Rotation3::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI);
    let contradicts = |v: &mut Verifier, k: u64, r: Rotation3<f64>| {
        matches!(
            v.on_result(k, Some((turned(truth(k), r), 0))),
            Verdict::Contradicts { in_a_row: 1, .. }
        )
    };
    // Two flips, 180° about y then about z: not one offset.
    assert!(contradicts(&mut v, 0, flip_y));
    assert!(contradicts(&mut v, 1, flip_z));
    // An agreement in between.
    assert!(matches!(
        v.on_result(2, Some((truth(2), 0))),
        Verdict::Agrees { confirmed: false }
    ));
    assert!(contradicts(&mut v, 3, flip_z));
    // The same offset, but more than three frames later.
    assert!(contradicts(&mut v, 7, flip_z));
    // A position off by more than 0.3 radii contradicts too.
    let mut far = truth(8);
    far.translation.z += 0.6;
    assert!(matches!(
        v.on_result(8, Some((far, 0))),
        Verdict::Contradicts { in_a_row: 1, off_deg } if off_deg < 1e-9
    ));
}

#[test]
fn disabled_nothing_is_due_and_bad_settings_are_named() {
    let off = VerifyConfig {
        enabled: false,
        ..VerifyConfig::default()
    };
    let mut v = Verifier::new(off, vec![Rotation3::identity()], 1.0);
    v.reset(Some(1), None);
    assert!(!v.due(0));
    VerifyConfig::default().validate().unwrap();
    for (config, name) in [
        (
            VerifyConfig {
                confirmations: 0,
                ..Default::default()
            },
            "confirmations",
        ),
        (
            VerifyConfig {
                contradictions: 0,
                ..Default::default()
            },
            "contradictions",
        ),
        (
            VerifyConfig {
                max_angle_deg: f64::NAN,
                ..Default::default()
            },
            "max_angle_deg",
        ),
        (
            VerifyConfig {
                max_offset_radii: -1.0,
                ..Default::default()
            },
            "max_offset_radii",
        ),
    ] {
        let e = config.validate().unwrap_err();
        assert!(e.starts_with(name), "{e}");
    }
}
