//! The replay node driven without processes: slots, skipped files, loops,
//! the end of the recording and oversized frames.

use super::*;
use spacepose_geometry::{CloudFormat, Point, write_cloud};
use spacepose_messages::{CloudHeader, Counters, Message, Names};
use spacepose_runtime::{Envelope, LocalBus, Outbox};
use std::path::Path;

const MS: i64 = 1_000_000;
/// An arbitrary wall-clock origin.
const T0: i64 = 1_700_000_000_000 * MS;

/// Collects the clouds the node sends.
#[derive(Default)]
struct Sent(Vec<(CloudHeader, Vec<Point>)>);

impl Outbox for Sent {
    fn message(&mut self, msg: &Message) -> anyhow::Result<()> {
        anyhow::bail!("{:?} is no output of pcd-replay", msg.topic())
    }

    fn cloud(&mut self, topic: Topic, header: CloudHeader, points: &[Point]) -> anyhow::Result<()> {
        assert_eq!(topic, Topic::RawCloud);
        self.0.push((header, points.to_vec()));
        Ok(())
    }

    fn json(&mut self, _: &str, _: &str) -> anyhow::Result<()> {
        anyhow::bail!("no ground link")
    }
}

/// `n` points of frame `k`, 1 ms apart from `k + 0.3` s.
fn points(k: usize, n: usize) -> Vec<Point> {
    (0..n)
        .map(|i| {
            Point::new(
                i as f32 * 0.001,
                0.0,
                10.0,
                1.0,
                k as f64 + 0.3 + i as f64 * 1e-3,
            )
        })
        .collect()
}

/// Frames `good` (500 + k points), `corrupt` files, and a truth.csv of one
/// second per frame.
fn recording(dir: &Path, good: &[usize], corrupt: &[usize]) {
    for &k in good {
        let path = dir.join(format!("frame_{k:06}.pcd"));
        write_cloud(&path, &points(k, 500 + k), CloudFormat::PcdBinary).unwrap();
    }
    for &k in corrupt {
        std::fs::write(dir.join(format!("frame_{k:06}.pcd")), "corrupt").unwrap();
    }
    let rows: String = (0..4)
        .map(|k| format!("{k},{}.28,{}.0\n", k, k + 1))
        .collect();
    std::fs::write(
        dir.join("truth.csv"),
        format!("frame,scan_start_s,scan_end_s\n{rows}"),
    )
    .unwrap();
}

fn node(dir: &Path, rate_hz: f64, looping: bool, exit_at_end: bool) -> PcdReplayNode {
    let config = PcdReplayConfig {
        input: dir.to_owned(),
        rate_hz,
        looping,
        exit_at_end,
        sensor_id: 4,
        ..PcdReplayConfig::default()
    };
    let info = NodeInfo {
        instance: spacepose_messages::Name::new("replay").unwrap(),
        names: Names::new("replaytest").unwrap(),
        heartbeat: Duration::from_millis(100),
    };
    PcdReplayNode::new(config, &info).unwrap()
}

/// One poll at `now_ns`: the flow and the clouds sent.
fn poll(
    n: &mut PcdReplayNode,
    c: &mut Counters,
    now_ns: i64,
) -> (Flow, Vec<(CloudHeader, Vec<Point>)>) {
    let mut out = Sent::default();
    let flow = n.poll(&mut Ctx::new(&mut out, c, now_ns));
    (flow, out.0)
}

#[test]
fn frames_go_out_on_their_slots_corrupt_files_are_skipped_and_loops_continue_the_clock() {
    let tmp = tempfile::tempdir().unwrap();
    recording(tmp.path(), &[0, 2], &[1]);
    let mut n = node(tmp.path(), 25.0, true, false);
    let mut c = Counters::default();
    assert!(
        poll(&mut n, &mut c, T0).1.is_empty(),
        "the first poll starts the clock"
    );
    assert_eq!(n.next_wake_ns(), Some(T0));

    let (flow, sent) = poll(&mut n, &mut c, T0);
    assert_eq!(flow, Flow::Continue);
    let (h0, p0) = &sent[0];
    assert_eq!(
        (h0.sequence, h0.scan_start_s, h0.scan_end_s, h0.sensor_id),
        (0, 0.28, 1.0, 4)
    );
    assert_eq!(*p0, points(0, 500));
    // Frame 1 is corrupt: counted when read ahead, no slot taken.
    assert_eq!(c.errors, 1);
    assert_eq!(n.next_wake_ns(), Some(T0 + 40 * MS));
    assert!(poll(&mut n, &mut c, T0 + 39 * MS).1.is_empty());
    let (_, sent) = poll(&mut n, &mut c, T0 + 40 * MS);
    assert_eq!(
        (sent[0].0.sequence, sent[0].0.scan_end_s, sent[0].1.len()),
        (1, 3.0, 502)
    );

    // The second pass: one period after the first one's end.
    let shift = (3.0 - 0.28) + 0.04;
    let (_, sent) = poll(&mut n, &mut c, T0 + 80 * MS);
    let (h2, p2) = &sent[0];
    assert_eq!(h2.sequence, 2);
    assert!((h2.scan_end_s - (1.0 + shift)).abs() < 1e-9);
    assert!((p2[0].t - (p0[0].t + shift)).abs() < 1e-9);
    assert_eq!(p2[0].x, p0[0].x);
    assert_eq!(
        (c.errors, c.frames_in, c.frames_out, c.last_frame),
        (2, 3, 3, 2)
    );
}

#[test]
fn the_recording_ends_with_an_exit_or_idle_heartbeats() {
    let tmp = tempfile::tempdir().unwrap();
    recording(tmp.path(), &[0, 1], &[]);
    // rate_hz = 0: the recorded period, one second.
    let mut n = node(tmp.path(), 0.0, false, true);
    assert_eq!(n.period(), Duration::from_secs(1));
    let mut c = Counters::default();
    poll(&mut n, &mut c, T0);
    assert_eq!(poll(&mut n, &mut c, T0).0, Flow::Continue);
    assert_eq!(n.next_wake_ns(), Some(T0 + 1000 * MS));
    let (flow, sent) = poll(&mut n, &mut c, T0 + 1000 * MS);
    assert_eq!((flow, sent[0].0.sequence), (Flow::Finished, 1));

    let mut n = node(tmp.path(), 0.0, false, false);
    poll(&mut n, &mut c, T0);
    poll(&mut n, &mut c, T0);
    assert_eq!(poll(&mut n, &mut c, T0 + 1000 * MS).0, Flow::Continue);
    assert_eq!((n.phase(), n.next_wake_ns()), (Phase::Idle, None));
    assert_eq!(
        poll(&mut n, &mut c, T0 + 5000 * MS),
        (Flow::Continue, vec![])
    );
}

#[test]
fn a_loop_over_unreadable_files_ends_instead_of_spinning() {
    let tmp = tempfile::tempdir().unwrap();
    recording(tmp.path(), &[], &[0, 1, 2]);
    let mut n = node(tmp.path(), 25.0, true, false);
    let mut c = Counters::default();
    assert_eq!(poll(&mut n, &mut c, T0), (Flow::Continue, vec![]));
    assert_eq!((n.phase(), c.errors, c.frames_in), (Phase::Idle, 3, 0));
    let mut n = node(tmp.path(), 25.0, true, true);
    assert_eq!(poll(&mut n, &mut c, T0).0, Flow::Finished);
}

#[test]
fn frames_without_a_time_field_get_derived_times_and_are_counted() {
    let tmp = tempfile::tempdir().unwrap();
    recording(tmp.path(), &[], &[]);
    let mut text = String::from(
        "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\n\
         HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n",
    );
    text.push_str("0 0 10\n1 0 10\n2 0 10\n");
    std::fs::write(tmp.path().join("frame_000001.pcd"), text).unwrap();
    let mut n = node(tmp.path(), 10.0, false, true);
    let mut c = Counters::default();
    poll(&mut n, &mut c, T0);
    let (_, sent) = poll(&mut n, &mut c, T0);
    assert_eq!((n.derived_times(), c.derived_times), (1, 1));
    let (header, points) = &sent[0];
    // truth.csv row 1: [1.28, 2.0]; times spread over it, never 0.
    assert_eq!((header.scan_start_s, header.scan_end_s), (1.28, 2.0));
    let t: Vec<f64> = points.iter().map(|p| p.t).collect();
    assert_eq!((t[0], t[2]), (1.28, 2.0));
    assert!((t[1] - 1.64).abs() < 1e-12);
}

#[test]
fn an_oversized_frame_is_counted_and_takes_its_sequence() {
    let tmp = tempfile::tempdir().unwrap();
    recording(tmp.path(), &[1], &[]);
    let big = points(0, MAX_POINTS + 1);
    write_cloud(
        tmp.path().join("frame_000000.pcd"),
        &big,
        CloudFormat::PcdBinary,
    )
    .unwrap();
    let mut n = node(tmp.path(), 10.0, false, true);
    let mut c = Counters::default();
    poll(&mut n, &mut c, T0);
    assert!(poll(&mut n, &mut c, T0).1.is_empty());
    assert_eq!((c.frames_in, c.rejected_oversized, c.frames_out), (1, 1, 0));
    let (flow, sent) = poll(&mut n, &mut c, T0 + 100 * MS);
    assert_eq!((flow, sent[0].0.sequence), (Flow::Finished, 1));
}

#[test]
fn on_a_local_bus_the_replay_feeds_ingest() {
    let tmp = tempfile::tempdir().unwrap();
    recording(tmp.path(), &[0, 1, 2], &[]);
    let mut bus = LocalBus::new();
    let replay = bus.add(node(tmp.path(), 10.0, false, false));
    let ingest = spacepose_ingest_node::IngestNode::new(
        Default::default(),
        &NodeInfo {
            instance: spacepose_messages::Name::new("ingest").unwrap(),
            names: Names::new("replaytest").unwrap(),
            heartbeat: Duration::from_millis(100),
        },
    );
    let ingest = bus.add(ingest.unwrap());
    let mut cropped = Vec::new();
    for now in [T0, T0, T0 + 100 * MS, T0 + 200 * MS] {
        bus.now_ns = now;
        for e in bus.poll() {
            if let Envelope::Cloud {
                topic: Topic::Cloud,
                header,
                ..
            } = e
            {
                cropped.push((header.sequence, header.scan_end_s));
            }
        }
    }
    assert_eq!(cropped, [(0, 1.0), (1, 2.0), (2, 3.0)]);
    assert_eq!(
        bus.node::<PcdReplayNode>(replay).unwrap().phase(),
        Phase::Idle
    );
    assert_eq!(bus.counters(ingest).unwrap().frames_out, 3);
}

/// A spacepose MCAP recording replays at recorded speed: each slot is the
/// step between the recorded scan starts, the scan times and points are the
/// recorded ones, and a pause longer than [`MAX_RECORDED_STEP_S`] takes one
/// period (1 s).
#[test]
fn an_mcap_recording_replays_at_the_recorded_steps() {
    use spacepose_foxglove::{RecordOptions, Recorder};
    use spacepose_messages::Cloud;
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("run.mcap");
    let starts = [5.0, 5.1, 5.35, 25.0];
    let mut rec = Recorder::create(&path, RecordOptions::default()).unwrap();
    for (k, start) in starts.iter().enumerate() {
        let pts: Vec<Point> = points(k, 50)
            .into_iter()
            .map(|mut p| {
                p.t = p.t - (k as f64 + 0.3) + start;
                p
            })
            .collect();
        let header = CloudHeader::new(k as u64 + 7, *start, start + 0.09);
        let cloud = Cloud {
            topic: Topic::RawCloud,
            header: &header,
            points: &pts,
        };
        assert!(rec.cloud(cloud).unwrap());
    }
    rec.close().unwrap();
    let mut n = node(&path, 0.0, false, true);
    let mut c = Counters::default();
    poll(&mut n, &mut c, T0);
    let mut now = T0;
    let mut got = Vec::new();
    for step_ms in [100, 250, 1000] {
        let (_, sent) = poll(&mut n, &mut c, now);
        got.extend(sent);
        assert_eq!(n.next_wake_ns(), Some(now + step_ms * MS));
        now += step_ms * MS;
    }
    let (flow, sent) = poll(&mut n, &mut c, now);
    got.extend(sent);
    assert_eq!(flow, Flow::Finished);
    let scans: Vec<(u64, f64, f64)> = got
        .iter()
        .map(|(h, _)| (h.sequence, h.scan_start_s, h.scan_end_s))
        .collect();
    let want: Vec<(u64, f64, f64)> = starts
        .iter()
        .enumerate()
        .map(|(k, s)| (k as u64, *s, s + 0.09))
        .collect();
    assert_eq!(scans, want);
    assert!((got[2].1[3].t - (5.35 + 3e-3)).abs() < 1e-9);
    assert_eq!((c.frames_out, c.errors, c.derived_times), (4, 0, 0));
}
