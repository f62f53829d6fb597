//! Tests of how [`TrackerNode`] starts from acquisitions: after a loss,
//! at the acquisition's own scan end, and late.

use super::*;

/// Seed 7's tumbling frames, one at a time, and a deblur node.
struct Tumbling {
    scenario: Box<dyn spacepose_scenario::Scenario>,
    sim: LidarSimulator,
    node: TrackerNode,
}

impl Tumbling {
    fn new() -> Self {
        let target = Arc::new(Target::builtin("deos").unwrap());
        let mut config = ScenarioConfig::default_for(ScenarioKind::Tumbling);
        config.seed = 7;
        let mut sensor = SensorConfig::livox_mid40();
        sensor.integration_time_s = 1.0;
        let instance = Name::new("tracker-t").unwrap();
        let tracker = TrackerConfig::with_mode(TrackingMode::Deblur);
        Tumbling {
            scenario: build(&config).unwrap(),
            sim: LidarSimulator::new(target, sensor).unwrap(),
            node: TrackerNode::with_model(tracker, fixture().model.clone(), instance, 200_000)
                .unwrap(),
        }
    }

    fn frames(&self, n: usize) -> Vec<Frame> {
        self.scenario
            .frame_end_times(n)
            .iter()
            .enumerate()
            .map(|(k, &t)| {
                self.sim.simulate(
                    &self.scenario.state_at(t),
                    &mut LidarSimulator::frame_rng(7, k as u64),
                )
            })
            .collect()
    }
}

#[test]
fn an_acquisition_at_its_own_scan_end_does_not_freeze_the_spin() {
    // A truth acquisition as lidar-sim sends it: the pose at the scan end of
    // frame 0. Placing it at the scan start and fusing frame 0 would teach
    // the filter ω ≈ 0 with confidence, and the 10°/s tumble of the
    // hexagonal body then slides to the 60° symmetric pose (seed 7, frames
    // 8-14 above 55° before the restart after the refining frame).
    let mut run = Tumbling::new();
    let mut errors_deg = Vec::new();
    for (k, f) in run.frames(14).iter().enumerate() {
        if k == 0 {
            run.node.on_acquisition(&truth_acquisition(f)).unwrap();
        }
        let r = run.node.track_frame(&header(k as u64, f), &f.points);
        assert_ne!(status(&r), WireStatus::Lost, "frame {k}: {}", r.reason);
        errors_deg.push(errors(&r, f).0);
    }
    let last = &errors_deg[10..];
    assert!(last.iter().all(|&e| e < 3.0), "{errors_deg:.1?}");
}

#[test]
fn an_acquisition_that_arrives_three_frames_late_is_caught_up() {
    // Template matching took longer than the frames: frame 0's acquisition
    // arrives after frames 1 and 2 were answered `lost`. The track replays
    // the kept frames 1 and 2 from it, so frame 3 starts one frame period
    // from a registered pose (without the catch-up it would start 30° off
    // on this 10°/s tumble, with zero rates).
    let mut run = Tumbling::new();
    let frames = run.frames(12);
    let mut errors_deg = Vec::new();
    for (k, f) in frames.iter().enumerate() {
        if k == 3 {
            assert_eq!(run.node.track.kept_frames(), 3);
            assert!(
                run.node
                    .on_acquisition(&truth_acquisition(&frames[0]))
                    .unwrap()
            );
        }
        let r = run.node.track_frame(&header(k as u64, f), &f.points);
        if k < 3 {
            assert_eq!(status(&r), WireStatus::Lost, "frame {k}");
            continue;
        }
        assert_eq!(status(&r), WireStatus::Tracking, "frame {k}: {}", r.reason);
        errors_deg.push(errors(&r, f).0);
    }
    assert_eq!(run.node.track.kept_frames(), 0);
    // deblur's start-up (zero rates) as after an on-time acquisition, then
    // the converged track.
    assert!(errors_deg.iter().all(|&e| e < 10.0), "{errors_deg:.1?}");
    assert!(errors_deg[4..].iter().all(|&e| e < 3.5), "{errors_deg:.1?}");
}

#[test]
fn after_a_loss_an_accepted_acquisition_restarts_the_track_and_a_rejected_one_does_not() {
    let f = &fixture().frames;
    let mut config = TrackerConfig::with_mode(TrackingMode::Ndt);
    config.loss.max_consecutive_degraded = 1;
    let instance = Name::new("tracker-t").unwrap();
    let mut node =
        TrackerNode::with_model(config, fixture().model.clone(), instance, 150_000).unwrap();
    node.on_acquisition(&truth_acquisition(&f[0])).unwrap();
    let r = node.track_frame(&header(0, &f[0]), &f[0].points);
    assert_eq!(status(&r), WireStatus::Tracking, "{}", r.reason);
    // Frame 1 seen 3 m to the side: inconsistent with the prediction, and
    // with one degraded frame allowed, the track is lost.
    let shifted: Vec<Point> = f[1]
        .points
        .iter()
        .map(|p| Point { x: p.x + 3.0, ..*p })
        .collect();
    let r = node.track_frame(&header(1, &f[1]), &shifted);
    assert_eq!(status(&r), WireStatus::Lost, "{}", r.reason);
    assert!(!node.is_tracking());
    // A rejected result (the init service's f_CONV check) changes nothing.
    let mut rejected = truth_acquisition(&f[1]);
    rejected.success = 0;
    assert!(!node.on_acquisition(&rejected).unwrap());
    let r = node.track_frame(&header(2, &f[2]), &f[2].points);
    assert_eq!(status(&r), WireStatus::Lost, "{}", r.reason);
    // The accepted reacquisition from frame 2 restarts the track on frame 3.
    assert!(node.on_acquisition(&truth_acquisition(&f[2])).unwrap());
    let r = node.track_frame(&header(3, &f[3]), &f[3].points);
    assert_eq!(status(&r), WireStatus::Tracking, "{}", r.reason);
    let (ang, pos) = errors(&r, &f[3]);
    assert!(ang < 1.0 && pos < 0.05, "{ang}° {pos} m");
    assert!(node.is_tracking());
}

#[test]
fn a_pending_acquisition_is_tracked_unconfirmed_until_its_own_confirmation() {
    use spacepose_messages::Verification;
    let f = &fixture().frames;
    let instance = Name::new("tracker-t").unwrap();
    let config = TrackerConfig::with_mode(TrackingMode::Ndt);
    let mut node =
        TrackerNode::with_model(config, fixture().model.clone(), instance, 150_000).unwrap();
    let mut pending = truth_acquisition(&f[0]);
    pending.verification = Verification::Pending as u8;
    pending.sequence = 4;
    assert!(node.on_acquisition(&pending).unwrap());
    assert!(node.is_unconfirmed());
    let r = node.track_frame(&header(0, &f[0]), &f[0].points);
    assert_eq!(status(&r), WireStatus::Unconfirmed, "{}", r.reason);
    assert_eq!(r.estimate.acquisition_sequence, pending.sequence);
    // A confirmation of another acquisition changes nothing, and restarts
    // nothing.
    let mut other = pending;
    other.verification = Verification::Confirms as u8;
    other.sequence += 5;
    assert!(!node.on_acquisition(&other).unwrap());
    let r = node.track_frame(&header(1, &f[1]), &f[1].points);
    assert_eq!(status(&r), WireStatus::Unconfirmed, "{}", r.reason);
    // Its own confirmation: `tracking` from the next frame, the track kept.
    let mut confirms = pending;
    confirms.verification = Verification::Confirms as u8;
    assert!(!node.on_acquisition(&confirms).unwrap());
    assert!(!node.is_unconfirmed());
    let r = node.track_frame(&header(2, &f[2]), &f[2].points);
    assert_eq!(status(&r), WireStatus::Tracking, "{}", r.reason);
    let (ang, pos) = errors(&r, &f[2]);
    assert!(ang < 3.0 && pos < 0.05, "{ang}° {pos} m");
    // A pending track that a trusted acquisition replaces is `tracking`.
    assert!(node.on_acquisition(&pending).unwrap());
    assert!(node.is_unconfirmed());
    assert!(node.on_acquisition(&truth_acquisition(&f[2])).unwrap());
    let r = node.track_frame(&header(3, &f[3]), &f[3].points);
    assert_eq!(status(&r), WireStatus::Tracking, "{}", r.reason);
}
