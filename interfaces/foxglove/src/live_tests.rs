//! A live view on an ephemeral loopback port, read by a WebSocket client
//! speaking the Foxglove protocol (`foxglove.sdk.v1`): advertise,
//! subscribe, binary message data.

use super::*;
use crate::cloud::POINT_STRIDE;
use foxglove::Decode;
use foxglove::messages::{PointCloud, PoseInFrame, SceneUpdate};
use serde_json::{Value, json};
use spacepose_geometry::Point;
use spacepose_messages::{CloudHeader, Name, PoseEstimate, Topic};
use std::collections::BTreeMap;
use std::net::TcpStream;
use std::time::{Duration, Instant};
use tungstenite::client::IntoClientRequest;
use tungstenite::{Message as Ws, WebSocket};

type Socket = WebSocket<TcpStream>;

fn connect(addr: SocketAddr) -> Socket {
    let stream = TcpStream::connect(addr).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_millis(20)))
        .unwrap();
    let mut req = format!("ws://{addr}").into_client_request().unwrap();
    req.headers_mut()
        .insert("sec-websocket-protocol", "foxglove.sdk.v1".parse().unwrap());
    let (socket, response) = tungstenite::client(req, stream).unwrap();
    assert_eq!(
        response.headers()["sec-websocket-protocol"],
        "foxglove.sdk.v1"
    );
    socket
}

/// The next frame, or `None` on a read timeout.
fn next(socket: &mut Socket) -> Option<Ws> {
    match socket.read() {
        Ok(m) => Some(m),
        Err(tungstenite::Error::Io(e))
            if matches!(
                e.kind(),
                std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
            ) =>
        {
            None
        }
        Err(e) => panic!("reading the live view: {e}"),
    }
}

/// Waits for the `advertise` of every topic of `wanted`, and subscribes to
/// each (subscription id = index + 1). Returns the advertised channels by topic.
fn subscribe(socket: &mut Socket, view: &mut LiveView, wanted: &[&str]) -> BTreeMap<String, Value> {
    let mut channels = BTreeMap::new();
    let deadline = Instant::now() + Duration::from_secs(10);
    while !wanted.iter().all(|t| channels.contains_key(*t)) {
        assert!(Instant::now() < deadline, "advertised: {channels:?}");
        view.message(&Message::Pose(PoseEstimate::new())).unwrap();
        if let Some(Ws::Text(text)) = next(socket) {
            let v: Value = serde_json::from_str(text.as_str()).unwrap();
            if v["op"] == "advertise" {
                for c in v["channels"].as_array().unwrap() {
                    channels.insert(c["topic"].as_str().unwrap().to_string(), c.clone());
                }
            }
        }
    }
    let subscriptions: Vec<Value> = wanted
        .iter()
        .enumerate()
        .map(|(i, t)| json!({"id": i + 1, "channelId": channels[*t]["id"]}))
        .collect();
    let msg = json!({"op": "subscribe", "subscriptions": subscriptions});
    socket.send(Ws::text(msg.to_string())).unwrap();
    channels
}

/// (subscription id, log time, payload) of a message-data frame.
fn message_data(bytes: &[u8]) -> Option<(u32, u64, &[u8])> {
    let (&op, rest) = bytes.split_first()?;
    if op != 0x01 || rest.len() < 12 {
        return None;
    }
    let id = u32::from_le_bytes(rest[..4].try_into().ok()?);
    let t = u64::from_le_bytes(rest[4..12].try_into().ok()?);
    Some((id, t, &rest[12..]))
}

fn tetra() -> TargetMesh {
    TargetMesh {
        name: "tetra".into(),
        vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        triangles: vec![[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]],
    }
}

const TOPICS: [&str; 4] = [
    topics::CLOUD,
    topics::POSE,
    topics::SCENE,
    topics::TRAJECTORY,
];

#[test]
fn a_client_subscribes_and_receives_decimated_clouds_poses_and_the_model() {
    let options = LiveOptions {
        max_points: 10,
        ..LiveOptions::default()
    };
    let mut view = LiveView::start("127.0.0.1:0".parse().unwrap(), options).unwrap();
    assert!(view.local_addr().ip().is_loopback());
    assert_ne!(view.local_addr().port(), 0);
    view.set_target(tetra());
    // The scene goes out with this message, before anyone listens: the
    // subscriber below must get it again.
    view.message(&Message::Pose(PoseEstimate::new())).unwrap();
    let mut socket = connect(view.local_addr());
    let channels = subscribe(&mut socket, &mut view, &TOPICS);
    assert_eq!(channels[topics::CLOUD]["schemaName"], "foxglove.PointCloud");
    assert_eq!(channels[topics::CLOUD]["encoding"], "protobuf");

    let points: Vec<Point> = (0..35)
        .map(|i| Point::new(i as f32, 0.0, 30.0, 0.5, 1.0))
        .collect();
    let mut got: BTreeMap<u32, Vec<u8>> = BTreeMap::new();
    let mut sensor_ns = 0;
    let deadline = Instant::now() + Duration::from_secs(10);
    for k in 0u64.. {
        if got.len() == TOPICS.len() {
            break;
        }
        assert!(Instant::now() < deadline, "received {:?}", got.keys());
        let t = 1.0 + 0.1 * k as f64;
        let header = CloudHeader::new(k, t - 0.1, t);
        let cloud = Cloud {
            topic: Topic::Cloud,
            header: &header,
            points: &points,
        };
        assert!(view.cloud(cloud).unwrap());
        let mut pose = PoseEstimate::new();
        (pose.sequence, pose.t_s, pose.p_sensor_target) = (k, t, [0.0, 0.0, 30.0]);
        pose.instance = Name::new("tracker").unwrap();
        view.message(&Message::Pose(pose)).unwrap();
        while let Some(frame) = next(&mut socket) {
            let Ws::Binary(bytes) = frame else { continue };
            if let Some((id, _, payload)) = message_data(&bytes) {
                got.insert(id, payload.to_vec());
            } else if bytes.len() == 9 && bytes[0] == 0x02 {
                // The protocol's `time`: the sensor clock.
                sensor_ns = u64::from_le_bytes(bytes[1..].try_into().unwrap());
            }
        }
    }
    let cloud = PointCloud::decode(got[&1].as_slice()).unwrap();
    assert_eq!(cloud.point_stride, POINT_STRIDE);
    // 35 points at a budget of 10: every 4th point, 9 of them.
    assert_eq!(cloud.data.len(), 9 * POINT_STRIDE as usize);
    let pose = PoseInFrame::decode(got[&2].as_slice()).unwrap();
    assert_eq!(pose.pose.unwrap().position.unwrap().z, 30.0);
    let scene = SceneUpdate::decode(got[&3].as_slice()).unwrap();
    assert_eq!(scene.entities.len(), 2);
    let track = PosesInFrame::decode(got[&4].as_slice()).unwrap();
    assert!(track.poses.len() >= 2, "{}", track.poses.len());
    assert!(sensor_ns >= 1_000_000_000, "time {sensor_ns}");
    assert_eq!(view.clients(), 1);
    let stats = view.stop();
    assert_eq!(stats.points, 9 * stats.clouds);
}

#[test]
fn frames_are_decimated_and_a_taken_port_is_an_error() {
    let options = LiveOptions {
        cloud_every: 3,
        trajectory: 2,
        ..LiveOptions::default()
    };
    let mut view = LiveView::start("127.0.0.1:0".parse().unwrap(), options).unwrap();
    let points = vec![Point::new(0.0, 0.0, 1.0, 0.0, 0.0); 4];
    for k in 0..7 {
        let header = CloudHeader::new(k, 0.0, 0.1);
        for topic in [Topic::RawCloud, Topic::Cloud] {
            let cloud = Cloud {
                topic,
                header: &header,
                points: &points,
            };
            view.cloud(cloud).unwrap();
        }
    }
    let stats = view.stats();
    // Cropped frames 0, 3, 6; no raw cloud by default.
    assert_eq!(
        (stats.clouds, stats.clouds_skipped, stats.points),
        (3, 11, 12)
    );
    for _ in 0..5 {
        view.message(&Message::Pose(PoseEstimate::new())).unwrap();
    }
    assert_eq!(view.trajectory.len(), 2);
    let taken = LiveView::start(view.local_addr(), LiveOptions::default());
    match taken {
        Err(RecordError::Server { addr, .. }) => assert_eq!(addr, view.local_addr().to_string()),
        Err(e) => panic!("wrong error: {e}"),
        Ok(_) => panic!("a second server on a taken port"),
    }
}
