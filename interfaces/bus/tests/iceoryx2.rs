//! iceoryx2 transport: clouds, messages, wake-up, capacity, isolation, cleanup.

#![allow(clippy::unwrap_used)] // tests may unwrap

mod common;

use common::unique_names;
use spacepose_bus::{Bus, BusError, WakeReason};
use spacepose_geometry::Point;
use spacepose_messages::{CloudHeader, Name, PoseEstimate, realtime_ns};
use std::io::{BufRead, BufReader};
use std::sync::mpsc;
use std::time::{Duration, Instant};

fn cloud(n: usize, seed: f32) -> Vec<Point> {
    (0..n)
        .map(|i| {
            let f = i as f32;
            Point::new(seed + f, -f, 0.5 * f, 0.1, 1.0 + 1e-6 * i as f64)
        })
        .collect()
}

#[test]
fn a_100k_point_cloud_crosses_threads_with_a_waitset_wake_up() {
    let names = unique_names("cloud");
    let sent = cloud(100_000, 7.0);
    let (ready_tx, ready_rx) = mpsc::channel();
    let sub_names = names.clone();
    let receiver = std::thread::spawn(move || {
        let bus = Bus::open(&sub_names, "receiver").unwrap();
        let sub = bus.cloud_subscriber(&sub_names.cloud()).unwrap();
        let mut waiter = bus.waitset_without_signals().unwrap();
        let id = waiter.attach(&sub).unwrap();
        ready_tx.send(()).unwrap();
        // Nothing published yet: the wait must time out, not spin.
        let reason = waiter.wait(Duration::from_millis(50)).unwrap();
        assert_eq!(reason, WakeReason::Timeout);
        ready_tx.send(()).unwrap();
        let start = Instant::now();
        let reason = waiter.wait(Duration::from_secs(10)).unwrap();
        assert_eq!(reason, WakeReason::Notified, "after {:?}", start.elapsed());
        assert_eq!(waiter.fired(), &[id]);
        let sample = sub.try_recv().unwrap().expect("a frame after the wake-up");
        assert!(sub.try_recv().unwrap().is_none());
        (*sample.header(), sample.points().to_vec(), realtime_ns())
    });
    ready_rx.recv().unwrap();
    ready_rx.recv().unwrap();
    let bus = Bus::open(&names, "sender").unwrap();
    let publisher = bus.cloud_publisher(&names.cloud(), 100_000).unwrap();
    assert_eq!(publisher.capacity(), 100_000);
    let header = CloudHeader::new(42, 1.0, 1.1);
    publisher.send(header, &sent).unwrap();
    let (got_header, got_points, received_ns) = receiver.join().unwrap();
    assert_eq!(got_header.sequence, 42);
    assert_eq!(got_header.point_count, 100_000);
    assert_eq!((got_header.scan_start_s, got_header.scan_end_s), (1.0, 1.1));
    assert!(got_header.published_ns > 0 && got_header.published_ns <= received_ns);
    assert_eq!(got_points, sent);
}

#[test]
fn an_oversized_frame_is_an_error_and_the_next_frame_still_goes() {
    let names = unique_names("oversize");
    let bus = Bus::open(&names, "node").unwrap();
    let sub = bus.cloud_subscriber(&names.raw_cloud()).unwrap();
    let publisher = bus.cloud_publisher(&names.raw_cloud(), 1000).unwrap();
    let err = publisher
        .send(CloudHeader::new(1, 0.0, 0.1), &cloud(1001, 0.0))
        .unwrap_err();
    assert!(
        matches!(
            err,
            BusError::CloudTooLarge {
                points: 1001,
                capacity: 1000,
                ..
            }
        ),
        "{err}"
    );
    assert!(sub.try_recv().unwrap().is_none());
    publisher
        .send(CloudHeader::new(2, 0.0, 0.1), &cloud(1000, 0.0))
        .unwrap();
    let frame = sub.try_recv().unwrap().unwrap();
    assert_eq!((frame.header().sequence, frame.len()), (2, 1000));
    // An empty frame is a valid frame (the consumer decides what to do with it).
    publisher
        .send_from_fn(CloudHeader::new(3, 0.0, 0.1), 0, |_| Point::default())
        .unwrap();
    drop(frame);
    let empty = sub.try_recv().unwrap().unwrap();
    assert!(empty.is_empty());
    assert_eq!(empty.header().sequence, 3);
}

#[test]
fn fixed_messages_are_delivered_and_stamped() {
    let names = unique_names("pose");
    let bus = Bus::open(&names, "node").unwrap();
    let sub = bus.subscriber::<PoseEstimate>(&names.pose()).unwrap();
    let mut waiter = bus.waitset_without_signals().unwrap();
    waiter.attach(&sub).unwrap();
    let publisher = bus.publisher::<PoseEstimate>(&names.pose()).unwrap();
    let before = realtime_ns();
    for seq in 0..5 {
        let mut m = PoseEstimate::new();
        m.sequence = seq;
        m.instance = Name::new("tracker-a").unwrap();
        publisher.send(&m).unwrap();
    }
    assert_eq!(
        waiter.wait(Duration::from_secs(5)).unwrap(),
        WakeReason::Notified
    );
    let got: Vec<PoseEstimate> = std::iter::from_fn(|| sub.try_recv().unwrap()).collect();
    assert_eq!(
        got.iter().map(|m| m.sequence).collect::<Vec<_>>(),
        vec![0, 1, 2, 3, 4]
    );
    assert!(got.iter().all(|m| m.published_ns >= before));
    assert_eq!(got[0].instance.as_str(), "tracker-a");
    // The events were consumed: the next wait times out.
    assert_eq!(
        waiter.wait(Duration::from_millis(20)).unwrap(),
        WakeReason::Timeout
    );
}

#[test]
fn two_deployments_never_meet() {
    let a = unique_names("iso-a");
    let b = unique_names("iso-b");
    let bus_a = Bus::open(&a, "node").unwrap();
    let bus_b = Bus::open(&b, "node").unwrap();
    // Same service name in both deployments on purpose.
    let service = "shared/pose";
    let sub_a = bus_a.subscriber::<PoseEstimate>(service).unwrap();
    let pub_b = bus_b.publisher::<PoseEstimate>(service).unwrap();
    pub_b.send(&PoseEstimate::new()).unwrap();
    assert!(sub_a.try_recv().unwrap().is_none());
    let pub_a = bus_a.publisher::<PoseEstimate>(service).unwrap();
    pub_a.send(&PoseEstimate::new()).unwrap();
    assert!(sub_a.try_recv().unwrap().is_some());
}

#[test]
fn bad_names_are_errors() {
    let names = unique_names("names");
    assert!(matches!(
        Bus::open(&names, ""),
        Err(BusError::InvalidName { .. })
    ));
    let bus = Bus::open(&names, "node").unwrap();
    assert!(bus.subscriber::<PoseEstimate>("").is_err());
}

const CHILD_ENV: &str = "SPACEPOSE_BUS_TEST_CHILD_PREFIX";

/// Runs only as the child of `dead_nodes_are_cleaned_up_at_start`.
#[test]
#[ignore = "helper process of dead_nodes_are_cleaned_up_at_start"]
fn child_process_that_gets_killed() {
    let Ok(prefix) = std::env::var(CHILD_ENV) else {
        return;
    };
    let names = spacepose_messages::Names::new(&prefix).unwrap();
    let bus = Bus::open(&names, "doomed").unwrap();
    let _publisher = bus.publisher::<PoseEstimate>(&names.pose()).unwrap();
    let _clouds = bus.cloud_publisher(&names.cloud(), 1000).unwrap();
    println!("ready");
    std::thread::sleep(Duration::from_secs(60));
}

#[test]
fn dead_nodes_are_cleaned_up_at_start() {
    let names = unique_names("dead");
    let mut child = std::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "child_process_that_gets_killed",
            "--ignored",
            "--nocapture",
        ])
        .env(CHILD_ENV, names.prefix())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let stdout = child.stdout.take().unwrap();
    let ready = BufReader::new(stdout)
        .lines()
        .map_while(Result::ok)
        .any(|l| l.contains("ready"));
    assert!(ready, "child never became ready");
    child.kill().unwrap(); // SIGKILL: no chance to clean up
    child.wait().unwrap();
    let bus = Bus::open(&names, "survivor").unwrap();
    assert!(
        bus.cleaned_dead_nodes() >= 1,
        "{}",
        bus.cleaned_dead_nodes()
    );
    // The services of the dead node can be used again.
    let sub = bus.subscriber::<PoseEstimate>(&names.pose()).unwrap();
    let publisher = bus.publisher::<PoseEstimate>(&names.pose()).unwrap();
    publisher.send(&PoseEstimate::new()).unwrap();
    assert!(sub.try_recv().unwrap().is_some());
    let again = Bus::open(&names, "later").unwrap();
    assert_eq!(again.cleaned_dead_nodes(), 0);
}
