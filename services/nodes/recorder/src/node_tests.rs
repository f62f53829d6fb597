//! Tests of [`RecorderNode`] driven as the runtime drives it, read back
//! with the `mcap` crate.

use super::*;
use spacepose_geometry::Point;
use spacepose_messages::{CloudHeader, Health, Name, Names, PoseEstimate, Topic};
use spacepose_runtime::{Collect, Counters};

const DESCRIPTOR: &str = r#"prefix = "rec"
[[service]]
name = "tracker-a"
kind = "tracker"
config = { target = "deos", tracker = { mode = "deblur" } }
"#;

fn info() -> NodeInfo {
    NodeInfo {
        instance: Name::new("recorder").unwrap(),
        names: Names::new("rec").unwrap(),
        heartbeat: std::time::Duration::from_millis(500),
    }
}

#[test]
fn a_run_is_recorded_with_its_configuration_and_closed_on_stop() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("run.mcap");
    let config = RecorderConfig {
        file: Some(file.clone()),
        descriptor: DESCRIPTOR.into(),
        ..RecorderConfig::default()
    };
    let mut node = RecorderNode::new(config, &info()).unwrap();
    let (mut out, mut counters) = (Collect::default(), Counters::default());
    let mut ctx = Ctx::new(&mut out, &mut counters, 0);
    let header = CloudHeader::new(0, 0.9, 1.0);
    let points = vec![Point::new(1.0, 2.0, 30.0, 0.5, 0.95); 3];
    node.on_cloud(
        Cloud {
            topic: Topic::Cloud,
            header: &header,
            points: &points,
        },
        &mut ctx,
    );
    let mut pose = PoseEstimate::new();
    pose.t_s = 1.0;
    node.on_message(&Message::Pose(pose), &mut ctx);
    pose.status = 9;
    node.on_message(&Message::Pose(pose), &mut ctx);
    let name = Name::new("tracker-a").unwrap();
    node.on_message(&Message::Health(Health::new(name, name, 1)), &mut ctx);
    node.stop(&mut ctx);
    assert_eq!(
        (
            counters.frames_in,
            counters.frames_out,
            counters.rejected_wire
        ),
        (4, 3, 1)
    );
    let bytes = std::fs::read(&file).unwrap();
    let summary = mcap::Summary::read(&bytes)
        .unwrap()
        .expect("closed: a summary");
    let topics: Vec<&str> = summary
        .channels
        .values()
        .map(|c| c.topic.as_str())
        .collect();
    assert!(topics.contains(&"/spacepose/scene"), "{topics:?}");
    let poses = mcap::MessageStream::new(&bytes)
        .unwrap()
        .filter(|m| m.as_ref().unwrap().channel.topic == "/spacepose/pose")
        .count();
    assert_eq!(poses, 1);
    let meta: Vec<&str> = summary
        .metadata_indexes
        .iter()
        .map(|m| m.name.as_str())
        .collect();
    assert_eq!(meta, ["spacepose.run", "spacepose.config.tracker-a"]);
    let config = mcap::read::metadata(&bytes, &summary.metadata_indexes[1]).unwrap();
    assert_eq!(config.metadata["kind"], "tracker");
    assert!(config.metadata["config.toml"].contains("deblur"));
    let attachment = mcap::read::attachment(&bytes, &summary.attachment_indexes[0]).unwrap();
    assert_eq!(attachment.name, "descriptor.toml");
    assert_eq!(&attachment.data[..], DESCRIPTOR.as_bytes());
    // A restarted recorder starts a new part beside the first.
    let config = RecorderConfig {
        file: Some(file),
        target: String::new(),
        ..RecorderConfig::default()
    };
    drop(RecorderNode::new(config, &info()).unwrap());
    assert!(dir.path().join("run.1.mcap").is_file());
}

#[test]
fn a_live_only_recorder_streams_without_a_file() {
    let live: LiveConfig = toml::from_str("listen = \"127.0.0.1:0\"\nmax_points = 2\n").unwrap();
    let config = RecorderConfig {
        live: Some(live),
        target: String::new(),
        ..RecorderConfig::default()
    };
    let mut node = RecorderNode::new(config, &info()).unwrap();
    assert!(node.recorder.is_none());
    let addr = node.live.as_ref().unwrap().local_addr();
    assert!(addr.ip().is_loopback() && addr.port() != 0);
    // The port is open: a TCP client connects.
    std::net::TcpStream::connect(addr).unwrap();
    let (mut out, mut counters) = (Collect::default(), Counters::default());
    let mut ctx = Ctx::new(&mut out, &mut counters, 0);
    let header = CloudHeader::new(0, 0.9, 1.0);
    let points = vec![Point::new(1.0, 2.0, 30.0, 0.5, 0.95); 5];
    for topic in [Topic::RawCloud, Topic::Cloud] {
        let cloud = Cloud {
            topic,
            header: &header,
            points: &points,
        };
        node.on_cloud(cloud, &mut ctx);
    }
    node.on_message(&Message::Pose(PoseEstimate::new()), &mut ctx);
    let stats = node.live.as_ref().unwrap().stats();
    // The raw cloud is not sent by default; 5 points at a budget of 2: 2.
    assert_eq!((stats.clouds, stats.points, stats.messages), (1, 2, 1));
    node.stop(&mut ctx);
    assert_eq!((counters.frames_in, counters.frames_out), (3, 2));
    // The SDK closes its listening socket asynchronously after the stop.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(5);
    while std::net::TcpStream::connect(addr).is_ok() {
        assert!(std::time::Instant::now() < deadline, "still listening");
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}
