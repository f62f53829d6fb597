//! The sensor node driven without processes: frames on the frame clock,
//! their truth, the truth acquisition, the end of a finite run and the
//! restart from a checkpoint.

use super::*;
use spacepose_geometry::Point;
use spacepose_ingest_node::IngestNode;
use spacepose_messages::{CloudHeader, Counters, Names, TruthMsg};
use spacepose_runtime::{Collect, Envelope, LocalBus};
use std::time::Duration;

const S: i64 = 1_000_000_000;
/// An arbitrary wall-clock origin.
const T0: i64 = 1_700_000_000 * S;

/// A small, fast run: 0.05 s frames without clutter.
fn config(frames: u64, rate_hz: f64) -> LidarSimConfig {
    LidarSimConfig {
        seed: 5,
        frames,
        rate_hz,
        integration_time_s: 0.05,
        clutter: false,
        sensor_id: 2,
        ..LidarSimConfig::default()
    }
}

fn info() -> NodeInfo {
    NodeInfo {
        instance: Name::new("sim-a").unwrap(),
        names: Names::new("simtest").unwrap(),
        heartbeat: Duration::from_millis(100),
    }
}

fn node(config: LidarSimConfig) -> LidarSimNode {
    LidarSimNode::new(config, &info()).unwrap()
}

/// One poll at `now_ns`: the flow and what was sent.
fn poll(node: &mut LidarSimNode, counters: &mut Counters, now_ns: i64) -> (Flow, Vec<Envelope>) {
    let mut out = Collect::default();
    let flow = node.poll(&mut Ctx::new(&mut out, counters, now_ns));
    (flow, out.0)
}

/// The frame sent in `sent`: its truth and its cloud.
fn frame_of(sent: &[Envelope]) -> (TruthMsg, CloudHeader, Vec<Point>) {
    let truth = sent.iter().find_map(|e| match e {
        Envelope::Message(Message::Truth(t)) => Some(*t),
        _ => None,
    });
    let cloud = sent.iter().find_map(|e| match e {
        Envelope::Cloud {
            topic: Topic::RawCloud,
            header,
            points,
        } => Some((*header, points.clone())),
        _ => None,
    });
    let (header, points) = cloud.unwrap();
    (truth.unwrap(), header, points)
}

#[test]
fn frames_go_out_on_their_slots_with_their_truth_and_the_run_ends() {
    let mut c = config(3, 2.0);
    c.truth_init = true;
    c.exit_at_end = true;
    let mut n = node(c);
    let mut counters = Counters::default();
    // The first poll chooses the start (frame 0, now) and sends nothing, so
    // the first heartbeat goes out before the first frame.
    assert_eq!(poll(&mut n, &mut counters, T0), (Flow::Continue, vec![]));
    assert_eq!(n.next_wake_ns(), Some(T0));

    let (flow, sent) = poll(&mut n, &mut counters, T0);
    assert_eq!(flow, Flow::Continue);
    let topics: Vec<_> = sent.iter().filter_map(Envelope::topic).collect();
    assert_eq!(topics, [Topic::Acquisition, Topic::Truth, Topic::RawCloud]);
    let Envelope::Message(Message::Acquisition(acq)) = sent[0] else {
        panic!("{:?}", sent[0]);
    };
    let first = n.source().frame(0).unwrap();
    assert_eq!(acq, truth_acquisition(&first, Name::new("sim-a").unwrap()));
    let (truth, header, points) = frame_of(&sent);
    assert_eq!(truth, truth_msg(0, &first.truth));
    assert_eq!(header, cloud_header(0, &first, 2));
    assert_eq!(points, first.points);
    assert!(points.len() > 100, "{} points", points.len());

    // Not before the next slot, half a second on.
    assert_eq!(n.next_wake_ns(), Some(T0 + S / 2));
    assert!(poll(&mut n, &mut counters, T0 + S / 4).1.is_empty());
    let (_, sent) = poll(&mut n, &mut counters, T0 + S / 2);
    let (truth, header, points) = frame_of(&sent);
    let second = n.source().frame(1).unwrap();
    assert_eq!(
        (truth, header.sequence, points),
        (truth_msg(1, &second.truth), 1, second.points)
    );
    assert_eq!(sent.len(), 2, "the acquisition is for the first frame only");

    // The last frame: the run is over.
    let (flow, sent) = poll(&mut n, &mut counters, T0 + S);
    assert_eq!((flow, frame_of(&sent).1.sequence), (Flow::Finished, 2));
    assert_eq!((counters.frames_in, counters.frames_out), (3, 3));
    assert_eq!((counters.last_frame, counters.errors), (2, 0));
}

#[test]
fn late_slots_are_not_caught_up_and_a_finished_run_idles() {
    let mut n = node(config(4, 2.0));
    let mut counters = Counters::default();
    poll(&mut n, &mut counters, T0);
    assert_eq!(poll(&mut n, &mut counters, T0).1.len(), 2);
    // 1.2 s late for frame 1: it goes out now and frame 2 at once (the
    // slot a period before now is the last one kept), then frame 3 a
    // period later: the two missed slots are not caught up.
    let (_, sent) = poll(&mut n, &mut counters, T0 + 17 * S / 10);
    assert_eq!(frame_of(&sent).1.sequence, 1);
    assert_eq!(n.next_wake_ns(), Some(T0 + 17 * S / 10));
    let (_, sent) = poll(&mut n, &mut counters, T0 + 17 * S / 10);
    assert_eq!(frame_of(&sent).1.sequence, 2);
    assert_eq!(n.next_wake_ns(), Some(T0 + 22 * S / 10));
    assert!(poll(&mut n, &mut counters, T0 + 21 * S / 10).1.is_empty());
    let (flow, sent) = poll(&mut n, &mut counters, T0 + 22 * S / 10);
    assert_eq!((flow, frame_of(&sent).1.sequence), (Flow::Continue, 3));
    // exit_at_end = false: idle, heartbeats only.
    assert_eq!((n.phase(), n.next_wake_ns()), (Phase::Idle, None));
    assert_eq!(
        poll(&mut n, &mut counters, T0 + 100 * S),
        (Flow::Continue, vec![])
    );
    assert_eq!((counters.frames_out, counters.last_frame), (4, 3));
}

#[test]
fn without_a_rate_every_poll_takes_the_next_frame() {
    let mut n = node(config(0, 0.0));
    let mut counters = Counters::default();
    poll(&mut n, &mut counters, T0);
    for k in 0..3 {
        let (flow, sent) = poll(&mut n, &mut counters, T0 + k);
        assert_eq!(
            (flow, frame_of(&sent).1.sequence),
            (Flow::Continue, k as u64)
        );
        assert_eq!(n.next_wake_ns(), Some(T0 + k), "due at once");
    }
}

#[test]
fn a_restarted_sensor_resumes_at_the_frame_now_due() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sim-a.sensorstate");
    let mut c = config(0, 1.0);
    c.checkpoint_file = Some(path.clone());
    let mut first = node(c.clone());
    let mut counters = Counters::default();
    poll(&mut first, &mut counters, T0);
    poll(&mut first, &mut counters, T0);
    poll(&mut first, &mut counters, T0 + S);
    assert_eq!(counters.last_frame, 1);
    drop(first);

    // Restarted 2.5 s after frame 1's slot: frames 2 and 3 are missed,
    // frame 4 is due half a second later, on the same grid.
    let mut second = node(c.clone());
    let restart = T0 + 35 * S / 10;
    assert!(poll(&mut second, &mut counters, restart).1.is_empty());
    assert_eq!(second.next_wake_ns(), Some(T0 + 4 * S));
    let (_, sent) = poll(&mut second, &mut counters, T0 + 4 * S);
    let (truth, header, points) = frame_of(&sent);
    let expected = second.source().frame(4).unwrap();
    assert_eq!((header.sequence, truth.sequence), (4, 4));
    assert_eq!(points, expected.points);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("frame=4\n"), "{text}");

    // Another configuration does not resume it; a corrupt file is counted.
    c.seed = 6;
    let mut other = node(c.clone());
    poll(&mut other, &mut counters, T0 + 5 * S);
    assert_eq!(other.phase(), Phase::Running(Resume::fresh(T0 + 5 * S)));
    std::fs::write(&path, "corrupt").unwrap();
    let mut broken = node(c);
    let errors = counters.errors;
    poll(&mut broken, &mut counters, T0 + 5 * S);
    assert_eq!(broken.phase(), Phase::Running(Resume::fresh(T0 + 5 * S)));
    assert_eq!(counters.errors, errors + 1);
}

#[test]
fn on_a_local_bus_the_frames_reach_ingest_in_order() {
    let mut bus = LocalBus::new();
    let sim = bus.add(node(config(2, 1.0)));
    let ingest_config = spacepose_ingest_node::IngestServiceConfig::default();
    let ingest = bus.add(IngestNode::new(ingest_config, &info()).unwrap());
    bus.now_ns = T0;
    assert!(bus.poll().is_empty());
    let frames: Vec<_> = [T0, T0 + S / 2, T0 + S]
        .into_iter()
        .flat_map(|now| {
            bus.now_ns = now;
            bus.poll()
        })
        .collect();
    // The polls return the sensor's own messages too; ingest's crops are
    // the clouds on the cloud topic.
    let sequences: Vec<u64> = frames
        .iter()
        .filter_map(|e| match e {
            Envelope::Cloud {
                topic: Topic::Cloud,
                header,
                ..
            } => Some(header.sequence),
            _ => None,
        })
        .collect();
    let raw = frames
        .iter()
        .filter(|e| e.topic() == Some(Topic::RawCloud))
        .count();
    assert_eq!(raw, 2);
    assert_eq!(sequences, [0, 1]);
    let n = bus.node::<LidarSimNode>(sim).unwrap();
    assert_eq!(n.phase(), Phase::Idle);
    assert_eq!(bus.counters(sim).unwrap().frames_out, 2);
    assert_eq!(bus.counters(ingest).unwrap().frames_in, 2);
}
