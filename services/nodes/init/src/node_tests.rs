//! The node driven as the runtime drives it (inputs, then a poll per
//! wake-up), with the real methods and worker thread, over an outbox that
//! keeps what it sends.

use super::*;
use crate::config::MethodKind;
use crate::error::InitError;
use crate::method::{MethodOutput, PoseAcquirer};
use spacepose_cnn::{DatasetConfig, GeneratedFrame, Generator};
use spacepose_geometry::{Point, Pose};
use spacepose_messages::{
    AcquisitionMethod, AcquisitionResult, CloudHeader, Names, PoseEstimate, Topic, WireStatus,
};
use spacepose_model::Target;
use spacepose_runtime::{Counters, Outbox};
use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

const NOW_NS: i64 = 1_000_000;

/// Keeps the messages sent; refuses every send while `failing`.
#[derive(Default)]
struct Sent {
    messages: Vec<Message>,
    failing: bool,
}

impl Outbox for Sent {
    fn message(&mut self, msg: &Message) -> anyhow::Result<()> {
        if self.failing {
            anyhow::bail!("the publisher is gone");
        }
        self.messages.push(*msg);
        Ok(())
    }

    fn cloud(&mut self, topic: Topic, _: CloudHeader, _: &[Point]) -> anyhow::Result<()> {
        anyhow::bail!("init publishes no cloud, got {topic:?}")
    }

    fn json(&mut self, key: &str, _: &str) -> anyhow::Result<()> {
        anyhow::bail!("init has no ground link, got {key}")
    }
}

/// The node, its counters and its outbox, at time [`NOW_NS`].
struct Harness {
    node: InitNode,
    counters: Counters,
    out: Sent,
}

impl Harness {
    fn new(node: InitNode) -> Self {
        Harness {
            node,
            counters: Counters::default(),
            out: Sent::default(),
        }
    }

    /// One wake-up: `input`, then the poll; returns the results sent.
    fn wake(&mut self, input: impl FnOnce(&mut InitNode, &mut Ctx<'_>)) -> Vec<AcquisitionResult> {
        let mut ctx = Ctx::new(&mut self.out, &mut self.counters, NOW_NS);
        input(&mut self.node, &mut ctx);
        assert_eq!(self.node.poll(&mut ctx), Flow::Continue);
        self.out
            .messages
            .drain(..)
            .map(|m| match m {
                Message::Acquisition(a) => a,
                other => panic!("init sent {other:?}"),
            })
            .collect()
    }

    /// Frame `sequence` (scan ending at `sequence + 0.5` s) arrives.
    fn cloud(&mut self, sequence: u64, points: &[Point]) -> Vec<AcquisitionResult> {
        let s = sequence as f64;
        let header = CloudHeader::new(sequence, s, s + 0.5);
        let cloud = Cloud {
            topic: Topic::Cloud,
            header: &header,
            points,
        };
        self.wake(|node, ctx| node.on_cloud(cloud, ctx))
    }

    /// A tracker estimate arrives (its result list must be empty: only a
    /// finished acquisition is published).
    fn estimate(&mut self, e: PoseEstimate) {
        let sent = self.wake(|node, ctx| node.on_message(&Message::Pose(e), ctx));
        assert!(sent.is_empty(), "{sent:?}");
    }

    /// Wakes (as the runtime does every [`BUSY_POLL_NS`] while busy) until
    /// the running acquisition is published; returns that one result.
    fn finished(&mut self) -> AcquisitionResult {
        assert!(self.node.busy(), "no acquisition runs");
        assert_eq!(self.node.next_wake_ns(), Some(NOW_NS + BUSY_POLL_NS));
        for _ in 0..30_000 {
            let sent = self.wake(|_, _| {});
            if let [one] = sent[..] {
                return one;
            }
            assert!(sent.is_empty(), "{sent:?}");
            std::thread::sleep(Duration::from_millis(2));
        }
        panic!("no acquisition result within 60 s");
    }
}

fn info(instance: &str) -> NodeInfo {
    NodeInfo {
        instance: Name::new(instance).unwrap(),
        names: Names::new("inittest").unwrap(),
        heartbeat: Duration::from_millis(100),
    }
}

/// The tracker's estimate of `sequence`, started at `started_ns`.
fn tracker(sequence: u64, status: WireStatus, started_ns: i64) -> PoseEstimate {
    let mut e = PoseEstimate::new();
    e.instance = Name::new("tracker").unwrap();
    e.sequence = sequence;
    e.status = status as u8;
    e.total_ms = 5.0;
    e.published_ns = started_ns + 5_000_000;
    e
}

fn deos_frame() -> GeneratedFrame {
    let deos = Arc::new(Target::builtin("deos").unwrap());
    let dataset = DatasetConfig {
        seed: 1003,
        count: 3,
        image_size: 64,
        roll_step_deg: 20.0,
        min_points: spacepose_cnn::DEFAULT_MIN_POINTS,
    };
    Generator::new(deos, dataset).unwrap().frame(1).unwrap()
}

fn assert_acquired(r: &AcquisitionResult, sequence: u64, frame: &GeneratedFrame) {
    assert_eq!(
        (r.sequence, r.t_s, r.success),
        (sequence, sequence as f64 + 0.5, 1)
    );
    assert_eq!(r.method, AcquisitionMethod::Cnn as u8);
    assert_eq!(r.instance.as_str(), "init-a");
    let (_, dist_m) = r.pose().unwrap().error_to(&frame.truth.t_sensor_target);
    assert!(dist_m < 0.15, "{dist_m} m off");
}

/// The CNN (the committed `deos` model, found from the crate's directory
/// through the source tree) acquires at start; a `lost` the tracker
/// computed before the result went out is ignored, a later loss and a
/// failed hand-over start new acquisitions on the held frame.
#[test]
fn acquires_at_start_and_again_after_a_loss_or_a_failed_handover() {
    // Without verifications (node_verify_tests.rs), which would keep the
    // worker busy while the track is unconfirmed.
    let mut config = InitServiceConfig {
        methods: vec![MethodKind::Cnn, MethodKind::TemplateMatching],
        ..InitServiceConfig::default()
    };
    config.verify.enabled = false;
    assert!(
        !Path::new("services/core/cnn/models/deos").exists(),
        "tests run in the crate's directory"
    );
    let mut h = Harness::new(InitNode::new(config, &info("init-a")).unwrap());
    let frame = deos_frame();
    assert_eq!(h.node.next_wake_ns(), None);

    // Frame 0, with two non-finite points: acquired, and the dropped
    // points counted.
    let mut points = frame.points.clone();
    points.extend([Point::new(f32::NAN, 0.0, 15.0, 1.0, 0.0); 2]);
    assert!(h.cloud(0, &points).is_empty());
    assert!(!h.node.busy(), "no tracker has said it does not track");
    h.estimate(tracker(0, WireStatus::Lost, NOW_NS));
    assert_acquired(&h.finished(), 0, &frame);
    assert_eq!(h.node.next_wake_ns(), None);
    assert!(matches!(
        h.node.phase(),
        Phase::HandedOver {
            frame: 0,
            published_ns: Some(_)
        }
    ));
    let c = h.counters;
    assert_eq!((c.frames_in, c.frames_out, c.last_frame), (1, 1, 0));
    assert_eq!(
        (c.rejected_non_finite, c.rejected_wire, c.errors),
        (1, 0, 0)
    );

    // Frame 1 was started before the result went out: its `lost` is ignored.
    assert!(h.cloud(1, &frame.points).is_empty());
    h.estimate(tracker(1, WireStatus::Lost, NOW_NS));
    assert!(matches!(h.node.phase(), Phase::HandedOver { .. }));
    assert!(!h.node.busy());
    h.estimate(tracker(2, WireStatus::Tracking, NOW_NS));
    assert_eq!(h.node.phase(), Phase::Tracking);

    // Frame 3 is lost: acquired again from the held frame 3.
    assert!(h.cloud(3, &frame.points).is_empty());
    assert!(!h.node.busy(), "no acquisition while the tracker tracks");
    h.estimate(tracker(3, WireStatus::Lost, NOW_NS));
    assert_eq!(h.node.phase(), Phase::Acquiring { not_before: 3 });
    assert_acquired(&h.finished(), 3, &frame);

    // Frame 4 is lost although the tracker started it after the result
    // went out: the hand-over failed, acquire again.
    assert!(h.cloud(4, &frame.points).is_empty());
    h.estimate(tracker(4, WireStatus::Lost, realtime_ns() + 1_000_000_000));
    assert_acquired(&h.finished(), 4, &frame);
    let s = h.node.stats();
    assert_eq!((s.attempts, s.accepted, s.rejected, s.losses), (3, 3, 0, 2));
    assert_eq!(s.last_delay_frames, Some(0));
    let c = h.counters;
    assert_eq!((c.frames_in, c.frames_out, c.last_frame), (4, 3, 4));
    assert_eq!(c.rejected_non_finite, 1);
}

/// An empty frame is an observation (a failure result, no counter); a
/// sparse frame with non-finite points is a failure that counts them; the
/// retry waits `retry_after_frames`; a bad estimate is refused and counted;
/// a result that cannot be sent is an error and no hand-over.
#[test]
fn empty_and_sparse_frames_fail_and_the_retry_waits_for_a_later_frame() {
    let mut config = InitServiceConfig::default();
    config.state.retry_after_frames = 2;
    let mut h = Harness::new(InitNode::new(config, &info("init")).unwrap());

    let mut bad = tracker(0, WireStatus::Tracking, NOW_NS);
    bad.status = 9;
    h.estimate(bad);
    assert_eq!(h.counters.rejected_wire, 1);

    assert!(h.cloud(0, &[]).is_empty());
    h.estimate(tracker(0, WireStatus::Lost, NOW_NS));
    let r = h.finished();
    assert_eq!((r.sequence, r.success), (0, 0));
    assert!(r.f_conv_m2.is_nan());
    assert_eq!(r.method, AcquisitionMethod::TemplateMatching as u8);
    assert_eq!(r.instance.as_str(), "init");
    let c = h.counters;
    assert_eq!(
        (c.rejected_non_finite, c.rejected_empty, c.frames_out),
        (0, 0, 1)
    );
    assert_eq!(h.node.phase(), Phase::Acquiring { not_before: 2 });

    let mut sparse: Vec<Point> = (0..10)
        .map(|i| Point::new(i as f32 * 0.1, 0.0, 15.0, 1.0, 0.0))
        .collect();
    sparse.extend([Point::new(0.0, f32::INFINITY, 15.0, 1.0, 0.0); 5]);
    assert!(h.cloud(1, &sparse).is_empty());
    assert!(!h.node.busy(), "frame 1 is before the retry");
    assert!(h.cloud(2, &sparse).is_empty());
    let r = h.finished();
    assert_eq!((r.sequence, r.success), (2, 0));
    let c = h.counters;
    assert_eq!((c.frames_in, c.frames_out, c.last_frame), (3, 2, 2));
    assert_eq!(
        (c.rejected_non_finite, c.rejected_wire, c.errors),
        (1, 1, 0)
    );
    let s = h.node.stats();
    assert_eq!((s.attempts, s.accepted, s.rejected), (2, 0, 2));
    assert_eq!(h.node.phase(), Phase::Acquiring { not_before: 4 });

    // The publisher fails: counted as an error, not as a frame out.
    assert!(h.cloud(4, &[]).is_empty());
    h.out.failing = true;
    for _ in 0..30_000 {
        if !h.node.busy() {
            break;
        }
        assert!(h.wake(|_, _| {}).is_empty());
        std::thread::sleep(Duration::from_millis(2));
    }
    assert!(!h.node.busy(), "the acquisition on frame 4 never finished");
    assert_eq!((h.counters.frames_out, h.counters.errors), (2, 1));
    assert_eq!(h.node.stats().attempts, 3);
    assert_eq!(h.node.phase(), Phase::Acquiring { not_before: 6 });
}

/// A method that panics (a bug).
struct Panics;

impl PoseAcquirer for Panics {
    fn method(&self) -> AcquisitionMethod {
        AcquisitionMethod::TemplateMatching
    }

    fn acquire(&self, _: &[Point]) -> Result<MethodOutput, InitError> {
        panic!("a method bug")
    }
}

/// A panic on the acquisition thread takes the node down with it (the
/// process exits with a failure and is restarted), never a silent service.
#[test]
fn a_panic_on_the_acquisition_thread_is_raised_by_the_node() {
    let chain = MethodChain::new(vec![Box::new(Panics)], 3).unwrap();
    let node = InitNode::with_chain(chain, InitConfig::default(), Name::new("init").unwrap());
    let mut h = Harness::new(node.unwrap());
    let points = vec![Point::new(0.0, 0.0, 15.0, 1.0, 0.0); 5];
    assert!(h.cloud(0, &points).is_empty());
    h.estimate(tracker(0, WireStatus::Lost, NOW_NS));
    let polled = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        for _ in 0..30_000 {
            h.wake(|_, _| {});
            std::thread::sleep(Duration::from_millis(2));
        }
    }));
    let panic = polled.expect_err("the node kept running without its worker");
    assert_eq!(panic.downcast_ref::<&str>(), Some(&"a method bug"));
}

/// On a `LocalBus` the graph delivers the cropped clouds and the tracker's
/// estimates to init (not the raw clouds), and its results come out.
#[test]
fn on_a_local_bus_init_reads_the_cropped_clouds_and_the_estimates() {
    let mut bus = spacepose_runtime::LocalBus::new();
    bus.now_ns = NOW_NS;
    let init = bus.add(InitNode::new(InitServiceConfig::default(), &info("init")).unwrap());
    let points = vec![Point::new(0.0, 0.0, 15.0, 1.0, 0.0); 5];
    bus.publish_cloud(
        Topic::RawCloud,
        CloudHeader::new(0, 0.0, 0.5),
        points.clone(),
    );
    bus.publish_cloud(Topic::Cloud, CloudHeader::new(1, 1.0, 1.5), points);
    assert!(bus.run().is_empty());
    assert_eq!(bus.counters(init).unwrap().frames_in, 1);
    // Every delivery is followed by a poll: estimates (the tracker has no
    // pose yet) wake the node until the result is out.
    for _ in 0..30_000 {
        bus.publish(Message::Pose(tracker(1, WireStatus::Lost, NOW_NS)));
        let sent = bus.run();
        if let [spacepose_runtime::Envelope::Message(Message::Acquisition(r))] = sent[..] {
            assert_eq!((r.sequence, r.t_s, r.success), (1, 1.5, 0));
            assert_eq!(bus.counters(init).unwrap().frames_out, 1);
            return;
        }
        assert!(sent.is_empty(), "{sent:?}");
        std::thread::sleep(Duration::from_millis(2));
    }
    panic!("no acquisition result within 60 s");
}

/// Restarted while the suite tracks: the first cloud comes before any
/// estimate (a tracker's estimate of a frame follows its cloud), and init
/// waits for the estimate, which says the suite tracks: no acquisition.
/// With no tracker answering at all, it acquires after
/// `instance_timeout_frames` frames.
#[test]
fn a_restarted_init_does_not_acquire_while_the_suite_tracks() {
    let frame = deos_frame();
    let mut h = Harness::new(InitNode::new(InitServiceConfig::default(), &info("init")).unwrap());
    assert!(h.cloud(40, &frame.points).is_empty());
    assert!(!h.node.busy(), "acquired before hearing the trackers");
    h.estimate(tracker(40, WireStatus::Tracking, NOW_NS));
    assert_eq!(h.node.phase(), Phase::Tracking);
    assert!(h.cloud(41, &frame.points).is_empty());
    assert!(!h.node.busy());
    assert_eq!(h.node.stats().attempts, 0);

    let mut h = Harness::new(InitNode::new(InitServiceConfig::default(), &info("init")).unwrap());
    let timeout = InitConfig::default().instance_timeout_frames;
    for k in 0..timeout {
        assert!(h.cloud(k, &[]).is_empty());
        assert!(!h.node.busy(), "frame {k}");
    }
    assert!(h.cloud(timeout, &[]).is_empty());
    assert_eq!(h.finished().sequence, timeout);
}

/// The verification of a hand-over, through the node.
#[path = "node_verify_tests.rs"]
mod verify;
