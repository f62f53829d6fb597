use super::*;

fn sm() -> InitStateMachine {
    InitStateMachine::new(InitConfig::default()).unwrap()
}

fn est(instance: &str, sequence: u64, status: WireStatus) -> EstimateInfo {
    EstimateInfo {
        instance: Name::new(instance).unwrap(),
        sequence,
        status,
        started_ns: None,
    }
}

fn tracker(sequence: u64, status: WireStatus) -> EstimateInfo {
    est("tracker", sequence, status)
}

#[test]
fn acquires_at_start_and_hands_over_to_the_tracker() {
    let mut s = sm();
    assert!(!s.wants(0), "nothing heard from the trackers yet");
    assert_eq!(s.on_frame(0), Event::None);
    // The uninitialised tracker reports lost: acquire from that frame.
    assert_eq!(
        s.on_estimate(&tracker(0, WireStatus::Lost)),
        Event::NoTrack { frame: 0 }
    );
    assert!(s.wants(0));
    assert_eq!(s.on_estimate(&tracker(0, WireStatus::Lost)), Event::None);
    assert_eq!(
        s.on_acquisition(0, true, Some(100)),
        Event::Accepted {
            frame: 0,
            delay_frames: Some(0)
        }
    );
    assert!(!s.wants(1));
    // Frames the tracker processed before it saw the result are still lost.
    assert_eq!(s.on_estimate(&tracker(1, WireStatus::Lost)), Event::None);
    assert_eq!(
        s.on_estimate(&tracker(2, WireStatus::Tracking)),
        Event::TrackerTracking { frame: 2 }
    );
    assert_eq!(s.phase(), Phase::Tracking);
    assert_eq!(s.stats().losses, 0);
}

#[test]
fn a_rejected_result_waits_for_a_later_frame() {
    let mut s = InitStateMachine::new(InitConfig {
        retry_after_frames: 2,
        ..InitConfig::default()
    })
    .unwrap();
    assert_eq!(
        s.on_acquisition(4, false, None),
        Event::Rejected {
            frame: 4,
            retry_from: 6
        }
    );
    assert!(!s.wants(4) && !s.wants(5) && s.wants(6) && s.wants(9));
    assert_eq!(s.stats().rejected, 1);
}

#[test]
fn a_loss_restarts_acquisition_never_from_an_older_frame() {
    let mut s = sm();
    s.on_acquisition(0, true, None);
    s.on_estimate(&tracker(1, WireStatus::Tracking));
    s.on_estimate(&tracker(2, WireStatus::Degraded));
    assert_eq!(s.phase(), Phase::Tracking);
    assert_eq!(
        s.on_estimate(&tracker(9, WireStatus::Lost)),
        Event::LossDetected { frame: 9 }
    );
    assert!(!s.wants(8), "a frame older than the loss");
    assert!(s.wants(9) && s.wants(10));
    // Still lost: no change, and the failure on frame 9 retries on 10.
    assert_eq!(s.on_estimate(&tracker(10, WireStatus::Lost)), Event::None);
    s.on_acquisition(9, false, None);
    assert!(!s.wants(9) && s.wants(10));
    assert_eq!(
        s.on_acquisition(11, true, None),
        Event::Accepted {
            frame: 11,
            delay_frames: Some(2)
        }
    );
    assert_eq!(s.stats().losses, 1);
    assert_eq!(s.stats().last_delay_frames, Some(2));
}

#[test]
fn a_handover_fails_when_the_tracker_loses_the_given_pose() {
    // By frame count: lost later than handover_frames after the result.
    let mut s = sm();
    s.on_acquisition(5, true, None);
    for k in 6..=8 {
        assert_eq!(s.on_estimate(&tracker(k, WireStatus::Lost)), Event::None);
    }
    assert_eq!(
        s.on_estimate(&tracker(9, WireStatus::Lost)),
        Event::HandoverFailed { frame: 9 }
    );
    assert!(s.wants(9));
    // By time: a frame the tracker started after the result was published.
    let mut s = sm();
    s.on_acquisition(5, true, Some(1_000));
    let mut before = tracker(6, WireStatus::Lost);
    before.started_ns = Some(900);
    assert_eq!(s.on_estimate(&before), Event::None);
    let mut after = tracker(7, WireStatus::Lost);
    after.started_ns = Some(1_100);
    assert_eq!(s.on_estimate(&after), Event::HandoverFailed { frame: 7 });
}

#[test]
fn a_tracker_that_tracks_on_its_own_ends_the_acquisition() {
    // E.g. the init service restarted while the suite was tracking: the
    // cloud of frame 40 comes first, then the estimate that says so.
    let mut s = sm();
    assert_eq!(s.on_frame(40), Event::None);
    assert!(!s.wants(40));
    assert_eq!(
        s.on_estimate(&tracker(40, WireStatus::Tracking)),
        Event::TrackerTracking { frame: 40 }
    );
    assert!(!s.wants(41));
}

#[test]
fn with_redundant_trackers_one_lost_instance_is_not_a_loss() {
    let mut s = sm();
    s.on_acquisition(0, true, None);
    s.on_estimate(&est("tracker-a", 1, WireStatus::Tracking));
    s.on_estimate(&est("tracker-b", 1, WireStatus::Tracking));
    assert_eq!(
        s.on_estimate(&est("tracker-a", 2, WireStatus::Lost)),
        Event::None
    );
    assert_eq!(
        s.on_estimate(&est("tracker-b", 2, WireStatus::Tracking)),
        Event::None
    );
    // b stops reporting (died): after instance_timeout_frames only a counts.
    assert_eq!(
        s.on_estimate(&est("tracker-a", 4, WireStatus::Lost)),
        Event::None
    );
    assert_eq!(
        s.on_estimate(&est("tracker-a", 6, WireStatus::Lost)),
        Event::LossDetected { frame: 6 }
    );
}

#[test]
fn zero_counts_are_errors() {
    for c in [
        InitConfig {
            retry_after_frames: 0,
            ..InitConfig::default()
        },
        InitConfig {
            handover_frames: 0,
            ..InitConfig::default()
        },
        InitConfig {
            instance_timeout_frames: 0,
            ..InitConfig::default()
        },
    ] {
        assert!(InitStateMachine::new(c).is_err());
    }
}

#[test]
fn with_no_tracker_answering_init_acquires_after_the_instance_timeout() {
    let mut s = sm();
    for k in 10..13 {
        assert_eq!(s.on_frame(k), Event::None);
        assert!(!s.wants(k));
    }
    assert_eq!(s.on_frame(13), Event::NoTrack { frame: 13 });
    assert!(s.wants(13) && !s.wants(12));
    assert_eq!(
        s.on_acquisition(13, true, None),
        Event::Accepted {
            frame: 13,
            delay_frames: Some(3)
        }
    );
    assert_eq!(s.stats().losses, 0);
}
