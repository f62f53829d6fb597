//! Tests of [`TrackerNode`] on simulated `deos` frames (test seeds).

use super::*;
use nalgebra::Vector3;
use spacepose_geometry::Point;
use spacepose_lidar_sim::{Frame, LidarSimulator, SensorConfig};
use spacepose_messages::convert::filter::state_of;
use spacepose_messages::{PoseEstimate, Topic, WireStatus, realtime_ns};
use spacepose_model::Target;
use spacepose_registration::NdtMapParams;
use spacepose_runtime::{Envelope, LocalBus};
use spacepose_scenario::{ScenarioConfig, ScenarioKind, build};
use spacepose_tracker::TrackError;
use std::sync::{Arc, OnceLock};

struct Fixture {
    model: TrackingModel,
    frames: Vec<Frame>,
}

fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let target = Arc::new(Target::builtin("deos").unwrap());
        let model =
            TrackingModel::build(&target.sample_surface(0.015, 0), &NdtMapParams::default())
                .unwrap();
        let mut config = ScenarioConfig::default_for(ScenarioKind::SlowSpin);
        config.seed = 21;
        let scenario = build(&config).unwrap();
        let mut sensor = SensorConfig::livox_mid40();
        sensor.integration_time_s = 1.0;
        let sim = LidarSimulator::new(target, sensor).unwrap();
        let frames = scenario
            .frame_end_times(4)
            .iter()
            .enumerate()
            .map(|(k, &t)| {
                sim.simulate(
                    &scenario.state_at(t),
                    &mut LidarSimulator::frame_rng(21, k as u64),
                )
            })
            .collect();
        Fixture { model, frames }
    })
}

fn node() -> TrackerNode {
    let config = TrackerConfig::with_mode(TrackingMode::Ndt);
    let instance = Name::new("tracker-t").unwrap();
    TrackerNode::with_model(config, fixture().model.clone(), instance, 150_000).unwrap()
}

fn header(seq: u64, f: &Frame) -> CloudHeader {
    let mut h = CloudHeader::new(seq, f.scan_start, f.scan_end);
    h.published_ns = realtime_ns();
    h
}

fn status(r: &FrameResult) -> WireStatus {
    r.estimate.wire_status().unwrap()
}

fn truth_acquisition(f: &Frame) -> AcquisitionResult {
    let mut a = AcquisitionResult::new();
    a.success = 1;
    a.t_s = f.scan_end;
    a.set_pose(&f.truth.t_sensor_target);
    a
}

fn errors(r: &FrameResult, f: &Frame) -> (f64, f64) {
    let (ang, pos) = r
        .estimate
        .pose()
        .unwrap()
        .error_to(&f.truth.t_sensor_target);
    (ang.to_degrees(), pos)
}

#[test]
fn frames_before_initialisation_and_bad_frames_are_lost_but_answered() {
    let f = &fixture().frames;
    let mut node = node();
    let r = node.track_frame(&header(0, &f[0]), &f[0].points);
    assert_eq!(status(&r), WireStatus::Lost);
    assert_eq!(r.estimate.sequence, 0);
    assert!(r.reason.contains("not initialised"), "{}", r.reason);
    assert!(node.on_acquisition(&truth_acquisition(&f[0])).unwrap());

    let nan = vec![Point::new(f32::NAN, 0.0, 1.0, 1.0, f[1].scan_end); 50];
    let r = node.track_frame(&header(1, &f[1]), &nan);
    assert_eq!(status(&r), WireStatus::Lost);
    assert_eq!(
        r.issue,
        Some(InputIssue::NonFinite {
            dropped: 50,
            kept: 0
        })
    );
    let big = vec![f[1].points[0]; 150_001];
    let r = node.track_frame(&header(1, &f[1]), &big);
    assert!(matches!(r.issue, Some(InputIssue::Oversized { .. })));

    // None of that hurt the track: the frame tracks from the acquisition.
    let r = node.track_frame(&header(1, &f[1]), &f[1].points);
    assert_eq!(status(&r), WireStatus::Tracking, "{}", r.reason);
    let (ang, pos) = errors(&r, &f[1]);
    assert!(ang < 3.0 && pos < 0.08, "{ang} deg {pos} m");
    assert!(r.estimate.total_ms > 0.0 && r.estimate.iterations > 0);
    assert!(r.estimate.covariance[0][0] > 0.0);

    // A few NaN points among good ones are dropped and the frame tracked.
    let mut some_nan = f[2].points.clone();
    some_nan[3].x = f32::NAN;
    some_nan[7].t = f64::INFINITY;
    let r = node.track_frame(&header(2, &f[2]), &some_nan);
    assert_eq!(
        r.issue,
        Some(InputIssue::NonFinite {
            dropped: 2,
            kept: some_nan.len() - 2
        })
    );
    assert_eq!(status(&r), WireStatus::Tracking, "{}", r.reason);
    // Going back in time is refused with an error, answered as lost.
    let r = node.track_frame(&header(0, &f[0]), &f[0].points);
    assert_eq!(status(&r), WireStatus::Lost);
    assert!(matches!(r.error, Some(TrackError::InvalidScanTimes { .. })));
    let r = node.track_frame(&header(3, &f[3]), &f[3].points);
    assert_eq!(status(&r), WireStatus::Tracking, "{}", r.reason);
}

#[test]
fn commands_switch_modes_and_reinitialise() {
    let f = &fixture().frames;
    let mut node = node();
    let me = Name::new("tracker-t").unwrap();
    let ground = Name::new("ground").unwrap();
    let mut c = Command::new(CommandKind::Mode, ground);
    c.mode = TrackingMode::CtNdt.code();
    c.target_instance = Name::new("tracker-b").unwrap();
    assert_eq!(node.on_command(&c).unwrap(), CommandOutcome::NotForMe);
    c.target_instance = me;
    assert_eq!(
        node.on_command(&c).unwrap(),
        CommandOutcome::ModeSet(TrackingMode::CtNdt)
    );
    assert_eq!(node.tracker().mode(), TrackingMode::CtNdt);
    c.mode = 9;
    assert!(node.on_command(&c).is_err());

    let mut reinit = Command::new(CommandKind::Reinit, ground);
    reinit.set_pose(&f[0].truth.t_sensor_target);
    assert_eq!(
        node.on_command(&reinit).unwrap(),
        CommandOutcome::ReinitFromPose
    );
    let r = node.track_frame(&header(1, &f[1]), &f[1].points);
    assert_eq!(r.estimate.mode, TrackingMode::CtNdt.code());
    assert_ne!(status(&r), WireStatus::Lost, "{}", r.reason);
    assert!(node.is_tracking());

    let drop = Command::new(CommandKind::Reinit, ground);
    assert_eq!(
        node.on_command(&drop).unwrap(),
        CommandOutcome::ReinitFromAcquisition
    );
    assert!(!node.is_tracking());
    let r = node.track_frame(&header(2, &f[2]), &f[2].points);
    assert_eq!(status(&r), WireStatus::Lost);
    assert_eq!(node.tracker().mode(), TrackingMode::CtNdt);
    let swap = Command::new(CommandKind::Swap, ground);
    assert_eq!(
        node.on_command(&swap).unwrap(),
        CommandOutcome::Ignored(CommandKind::Swap)
    );
}

#[test]
fn filter_states_are_followed_once_tracking() {
    let f = &fixture().frames;
    let mut node = node();
    let mut filter = spacepose_filter::RelativeMotionFilter::new(Default::default()).unwrap();
    filter
        .initialize(
            f[1].scan_end,
            &f[1].truth.t_sensor_target,
            Vector3::zeros(),
            Vector3::zeros(),
        )
        .unwrap();
    let state = state_of(&filter, 1);
    // Told to wait for an acquisition: the state is not followed yet.
    let ground = Name::new("ground").unwrap();
    node.on_command(&Command::new(CommandKind::Reinit, ground))
        .unwrap();
    node.on_filter_state(&state).unwrap();
    assert!(!node.is_tracking());
    // A fresh instance (restarted or swapped in) warm-starts from the
    // filter service's state and tracks the next frame.
    let mut fresh = self::node();
    fresh.on_filter_state(&state).unwrap();
    // Not before a frame that starts after the state's time.
    let r = fresh.track_frame(&header(1, &f[1]), &f[1].points);
    assert_eq!(status(&r), WireStatus::Lost);
    assert!(!fresh.is_tracking());
    let r = fresh.track_frame(&header(2, &f[2]), &f[2].points);
    assert_eq!(status(&r), WireStatus::Tracking, "{}", r.reason);
    let (ang, _) = errors(&r, &f[2]);
    assert!(ang < 2.0, "warm-started frame error {ang} deg");
    node.on_acquisition(&truth_acquisition(&f[0])).unwrap();
    node.track_frame(&header(1, &f[1]), &f[1].points);
    node.on_filter_state(&state).unwrap();
    node.track.apply_filter_state(&header(2, &f[2])).unwrap();
    let p = node.tracker().predict_at(f[1].scan_end).unwrap();
    let (ang, pos) = p.pose.error_to(&f[1].truth.t_sensor_target);
    assert!(
        ang < 1e-9 && pos < 1e-9,
        "the service's state replaced the local one"
    );
    let mut bad = state;
    bad.p_sensor_target[0] = f64::NAN;
    assert!(node.on_filter_state(&bad).is_err());
}

#[test]
fn a_frame_without_the_target_is_lost_at_once_and_fuses_nothing() {
    let f = &fixture().frames;
    for (what, cloud) in [
        ("empty (sensor looked away)", Vec::new()),
        ("10 points", f[2].points[..10].to_vec()),
    ] {
        let mut node = node();
        node.on_acquisition(&truth_acquisition(&f[0])).unwrap();
        node.track_frame(&header(0, &f[0]), &f[0].points);
        let r = node.track_frame(&header(1, &f[1]), &f[1].points);
        assert_eq!(status(&r), WireStatus::Tracking, "{}", r.reason);
        let before = node.tracker().predict_at(f[2].scan_end).unwrap();

        // Lost on this very frame (not after 5 degraded ones), and not as
        // bad input: "target not seen" is an observation.
        let r = node.track_frame(&header(2, &f[2]), &cloud);
        assert_eq!(status(&r), WireStatus::Lost, "{what}");
        assert!(r.reason.contains("no measurement"), "{what}: {}", r.reason);
        assert!(r.issue.is_none() && r.error.is_none(), "{what}: {r:?}");
        assert!(!node.is_tracking());
        // No measurement on the wire: the pose is the filter prediction,
        // no registration figures, covariance unknown (zeros).
        let e = &r.estimate;
        assert_eq!((e.sequence, e.t_s), (2, f[2].scan_end));
        assert_eq!((e.iterations, e.inliers), (0, 0), "{what}");
        assert!(e.points_used as usize <= cloud.len(), "{what}");
        assert!(e.covariance.iter().flatten().all(|v| *v == 0.0));
        let (ang, pos) = e.pose().unwrap().error_to(&before.pose);
        assert!(ang < 1e-6 && pos < 1e-6, "{what}: {ang} rad {pos} m");
        // Nothing was fused: the filter predicts exactly as before.
        let after = node.tracker().predict_at(f[2].scan_end).unwrap();
        let (ang, pos) = after.pose.error_to(&before.pose);
        assert!(ang < 1e-12 && pos < 1e-12, "{what}: the filter moved");
        assert_eq!(after.covariance, before.covariance, "{what}");
        assert_eq!(after.w_target, before.w_target, "{what}");

        // The target is back, but the track waits for a reacquisition...
        let r = node.track_frame(&header(3, &f[3]), &f[3].points);
        assert_eq!(status(&r), WireStatus::Lost, "{what}: {}", r.reason);
        // ... which restarts it.
        assert!(node.on_acquisition(&truth_acquisition(&f[2])).unwrap());
        let r = node.track_frame(&header(3, &f[3]), &f[3].points);
        assert_eq!(status(&r), WireStatus::Tracking, "{what}: {}", r.reason);
        assert!(node.is_tracking());
    }
}

/// The estimates among what a [`LocalBus`] run sent.
fn poses(sent: &[Envelope]) -> Vec<PoseEstimate> {
    sent.iter()
        .filter_map(|e| match e {
            Envelope::Message(Message::Pose(p)) => Some(*p),
            _ => None,
        })
        .collect()
}

fn publish_frame(bus: &mut LocalBus, seq: u64, f: &Frame, points: Vec<Point>) -> PoseEstimate {
    bus.publish_cloud(Topic::Cloud, header(seq, f), points);
    let sent = poses(&bus.run());
    assert_eq!(sent.len(), 1, "one estimate per cloud");
    sent[0]
}

#[test]
fn on_a_local_bus_every_cloud_is_answered_and_counted_as_the_process_counts_it() {
    let f = &fixture().frames;
    let mut bus = LocalBus::new();
    let at = bus.add(node());
    let tracker = |bus: &LocalBus| bus.node::<TrackerNode>(at).unwrap().state();

    let e = publish_frame(&mut bus, 0, &f[0], f[0].points.clone());
    assert_eq!(
        (e.sequence, e.wire_status().unwrap()),
        (0, WireStatus::Lost)
    );
    assert_eq!(e.instance.as_str(), "tracker-t");
    assert!(bus.node::<TrackerNode>(at).unwrap().last_output().is_none());
    assert_eq!(tracker(&bus), ServiceState::Degraded);

    // The acquisition applies to the cloud published after it.
    bus.publish(Message::Acquisition(truth_acquisition(&f[0])));
    let e = publish_frame(&mut bus, 1, &f[1], f[1].points.clone());
    assert_eq!(e.wire_status().unwrap(), WireStatus::Tracking);
    let node = bus.node::<TrackerNode>(at).unwrap();
    let out = node.last_output().expect("frame 1 reached the tracker");
    assert!(out.has_measurement());
    assert_eq!((out.t, out.iterations()), (e.t_s, e.iterations as usize));
    assert_eq!(out.points_used, e.points_used as usize);
    assert_eq!(tracker(&bus), ServiceState::Running);

    // A NaN-only frame: lost, counted, not handed to the tracker.
    let nan = vec![Point::new(f32::NAN, 0.0, 1.0, 1.0, f[2].scan_end); 20];
    let e = publish_frame(&mut bus, 2, &f[2], nan);
    assert_eq!(e.wire_status().unwrap(), WireStatus::Lost);
    assert!(bus.node::<TrackerNode>(at).unwrap().last_output().is_none());

    // Refused control messages are counted in rejected_wire and send nothing.
    let mut bad_command = Command::new(CommandKind::Mode, Name::new("ground").unwrap());
    bad_command.mode = TrackingMode::MAX_CODE + 1;
    let mut bad_state = state_of(
        &spacepose_filter::RelativeMotionFilter::new(Default::default()).unwrap(),
        1,
    );
    bad_state.initialized = 1;
    bad_state.t_s = f64::NAN;
    bus.publish(Message::Command(bad_command));
    bus.publish(Message::FilterState(bad_state));
    assert!(bus.run().is_empty());

    let e = publish_frame(&mut bus, 3, &f[3], f[3].points.clone());
    assert_eq!(e.wire_status().unwrap(), WireStatus::Tracking);
    let c = bus.counters(at).unwrap();
    assert_eq!((c.frames_in, c.frames_out, c.last_frame), (4, 4, 3));
    assert_eq!((c.rejected_non_finite, c.rejected_wire), (1, 2));
    assert_eq!((c.rejected_oversized, c.errors), (0, 0));
}

#[test]
fn the_runtime_builds_the_node_from_its_configuration_and_instance() {
    let config: TrackerServiceConfig =
        toml::from_str("instance = \"tracker-x\"\nmax_points = 1000\n[tracker]\nmode = \"ndt\"\n")
            .unwrap();
    let info = NodeInfo {
        instance: Name::new("tracker-y").unwrap(),
        names: spacepose_messages::Names::new("test").unwrap(),
        heartbeat: std::time::Duration::from_millis(100),
    };
    let node = <TrackerNode as Node>::new(config, &info).unwrap();
    assert_eq!(node.tracker().mode(), TrackingMode::Ndt);
    assert_eq!(node.state(), ServiceState::Degraded);
    let mut bus = LocalBus::new();
    let at = bus.add(node);
    let f = &fixture().frames;
    // The runtime's instance (here --instance over the file's) names the
    // estimates, and the file's max_points applies.
    let e = publish_frame(&mut bus, 0, &f[0], f[0].points.clone());
    assert_eq!(e.instance.as_str(), "tracker-y");
    assert_eq!(e.mode, TrackingMode::Ndt.code());
    assert!(f[0].points.len() > 1000);
    assert_eq!(bus.counters(at).unwrap().rejected_oversized, 1);
}

#[path = "node_acquisition_tests.rs"]
mod acquisition;
