use super::*;

fn pose(instance: &str, sequence: u64, status: &str, z: f64) -> TelemetryPose {
    let mut p = TelemetryPose::from_wire(&spacepose_messages::PoseEstimate::new()).unwrap();
    p.instance = instance.into();
    p.sequence = sequence;
    p.status = status.into();
    p.q_sensor_target = [1.0, 0.0, 0.0, 0.0];
    p.p_sensor_target_m = [0.0, 0.0, z];
    p
}

fn acquisition(sequence: u64) -> AcquisitionRecord {
    let mut m = spacepose_messages::AcquisitionResult::new();
    m.sequence = sequence;
    m.success = 1;
    AcquisitionRecord::from_wire(&m).unwrap()
}

fn recorded(raw: std::ops::Range<u64>, poses: Vec<TelemetryPose>) -> RecordedRun {
    RecordedRun {
        acquisitions: vec![acquisition(raw.start + 2)],
        raw_sequences: raw.collect(),
        poses,
        ..RecordedRun::default()
    }
}

#[test]
fn identical_poses_are_reproduced_in_the_recordings_numbering() {
    // The recording's raw clouds are 10, 11, 12; the replay numbers them 0, 1, 2.
    let rec = recorded(
        10..13,
        vec![pose("t", 10, "lost", 0.0), pose("t", 12, "tracking", 40.0)],
    );
    let replay = vec![pose("t", 0, "lost", 0.0), pose("t", 2, "tracking", 40.0)];
    let c = compare(&rec, replay, vec![acquisition(2)]);
    assert!(c.reproduced(), "{c:?}");
    assert_eq!((c.matched, c.identical, c.first_difference), (2, 2, None));
    assert_eq!((c.max_angle_deg, c.max_position_mm), (0.0, 0.0));
    assert!(c.reasons.is_empty());
}

#[test]
fn differences_are_measured_and_explained() {
    let rec = recorded(
        0..3,
        vec![
            pose("t", 0, "lost", 0.0),
            pose("t", 1, "tracking", 40.0),
            pose("t", 2, "tracking", 40.0),
        ],
    );
    // Frame 1 lost in the replay, frame 2 3 mm off, an extra pose of frame 5.
    let replay = vec![
        pose("t", 0, "lost", 0.0),
        pose("t", 1, "lost", 0.0),
        pose("t", 2, "tracking", 40.003),
        pose("t", 5, "tracking", 40.0),
    ];
    let c = compare(&rec, replay.clone(), vec![acquisition(1)]);
    assert!(!c.reproduced());
    assert_eq!((c.matched, c.same_status, c.identical), (3, 2, 1));
    assert_eq!((c.first_difference, c.extra_in_replay), (Some(1), 1));
    assert_eq!(
        c.status_differences,
        vec![(1, "tracking".to_string(), "lost".to_string())]
    );
    assert!((c.max_position_mm - 40_000.0).abs() < 1e-6);
    assert_eq!(c.max_angle_deg, 0.0);
    assert!(c.reasons.iter().any(|r| r.contains("acquisitions")));
    assert!(c.reasons.iter().any(|r| r.contains("not recorded")));
    // Same acquisitions and frames: the remaining cause is named.
    let c = compare(&rec, replay[..3].to_vec(), vec![acquisition(2)]);
    assert_eq!(c.reasons.len(), 1);
    assert!(
        c.reasons[0].contains("filter service's state"),
        "{:?}",
        c.reasons
    );
}

#[test]
fn a_decimated_recording_says_so() {
    let mut rec = recorded(0..1, vec![pose("t", 0, "lost", 0.0)]);
    rec.raw_sequences = vec![0, 2, 4];
    assert_eq!(rec.raw_gaps(), 2);
    let c = compare(&rec, vec![pose("t", 0, "lost", 0.0)], vec![]);
    assert!(c.reasons[0].contains("decimated"), "{:?}", c.reasons);
}

#[test]
fn a_small_rotation_is_measured_exactly() {
    let rec = recorded(0..1, vec![pose("t", 0, "tracking", 40.0)]);
    let mut p = pose("t", 0, "tracking", 40.0);
    let half = 1e-9f64.to_radians() / 2.0; // 1e-9 deg about z
    p.q_sensor_target = [half.cos(), 0.0, 0.0, half.sin()];
    let c = compare(&rec, vec![p], vec![acquisition(2)]);
    assert!(
        (c.max_angle_deg - 1e-9).abs() < 1e-15,
        "{}",
        c.max_angle_deg
    );
}

#[test]
fn a_confirmation_on_another_frame_is_named() {
    let statuses = |list: &[&str]| -> Vec<TelemetryPose> {
        (0u64..)
            .zip(list)
            .map(|(k, s)| pose("t", k, s, 40.0))
            .collect()
    };
    let rec = recorded(
        0..4,
        statuses(&["unconfirmed", "unconfirmed", "tracking", "tracking"]),
    );
    let replay = statuses(&["unconfirmed", "unconfirmed", "unconfirmed", "tracking"]);
    let c = compare(&rec, replay, vec![acquisition(2)]);
    assert_eq!(c.recorded_confirmations, vec![("t".to_string(), 2)]);
    assert_eq!(c.replayed_confirmations, vec![("t".to_string(), 3)]);
    assert_eq!(c.status_differences.len(), 1);
    assert_eq!(c.max_angle_deg, 0.0);
    assert_eq!(c.reasons.len(), 1, "{:?}", c.reasons);
    assert!(c.reasons[0].contains("unconfirmed"), "{:?}", c.reasons);
}
