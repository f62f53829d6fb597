//! `spacepose up --view`: the running suite streams its channels live on a
//! Foxglove WebSocket server. A client speaking the Foxglove WebSocket
//! protocol (subprotocol `foxglove.sdk.v1`: JSON `advertise`, `subscribe`,
//! binary message data) connects, subscribes to every channel, and receives
//! decoded point clouds within the point budget, the estimated and true
//! poses, the transforms, the trajectory, the model and the status JSON.
//! The server listens on loopback only, and the CLI refuses a view beyond
//! it. Prints the bytes per second of the link at the default decimation.
#![allow(clippy::unwrap_used)] // test helpers

use foxglove::Decode;
use foxglove::messages::{FrameTransform, PointCloud, PoseInFrame, PosesInFrame, SceneUpdate};
use serde_json::{Value, json};
use spacepose_e2e::net::listening_tcp;
use spacepose_e2e::*;
use std::collections::BTreeMap;
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};
use tungstenite::client::IntoClientRequest;
use tungstenite::{Message as Ws, WebSocket};

type Socket = WebSocket<TcpStream>;

/// Frames of the sensor: more than the test watches, so the suite is still
/// running when the window ends (brought down by the test).
const FRAMES: u64 = 200;
/// How long the client counts the bytes of the link.
const WINDOW: Duration = Duration::from_secs(8);

/// A client of the live view: connected, handshake done (retried until the
/// server answers).
fn connect(addr: SocketAddr) -> Socket {
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        if let Ok(stream) = TcpStream::connect(addr) {
            stream
                .set_read_timeout(Some(Duration::from_millis(50)))
                .unwrap();
            let mut req = format!("ws://{addr}").into_client_request().unwrap();
            req.headers_mut()
                .insert("sec-websocket-protocol", "foxglove.sdk.v1".parse().unwrap());
            let (socket, response) = tungstenite::client(req, stream).unwrap();
            assert_eq!(
                response.headers()["sec-websocket-protocol"],
                "foxglove.sdk.v1"
            );
            return socket;
        }
        assert!(Instant::now() < deadline, "no live view on {addr}");
        std::thread::sleep(Duration::from_millis(100));
    }
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

/// The advertised channels by topic, once every topic of `wanted` is.
fn advertised(socket: &mut Socket, wanted: &[&str]) -> BTreeMap<String, Value> {
    let mut channels = BTreeMap::new();
    let deadline = Instant::now() + Duration::from_secs(10);
    while !wanted.iter().all(|t| channels.contains_key(*t)) {
        assert!(
            Instant::now() < deadline,
            "advertised: {:?}",
            channels.keys()
        );
        if let Some(Ws::Text(text)) = next(socket) {
            let v: Value = serde_json::from_str(text.as_str()).unwrap();
            if v["op"] == "advertise" {
                for c in v["channels"].as_array().unwrap() {
                    channels.insert(c["topic"].as_str().unwrap().to_string(), c.clone());
                }
            }
        }
    }
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

/// What the client received on one topic: (log time, payload) per message.
type Received = BTreeMap<String, Vec<(u64, Vec<u8>)>>;

/// Subscribes to every advertised channel (subscription id = channel id)
/// and collects for [`WINDOW`]; returns the messages and the bytes of
/// message data received.
fn collect(socket: &mut Socket, channels: &BTreeMap<String, Value>) -> (Received, u64) {
    let subscriptions: Vec<Value> = channels
        .values()
        .map(|c| json!({"id": c["id"], "channelId": c["id"]}))
        .collect();
    let msg = json!({"op": "subscribe", "subscriptions": subscriptions});
    socket.send(Ws::text(msg.to_string())).unwrap();
    let topic_of: BTreeMap<u64, &String> = channels
        .iter()
        .map(|(t, c)| (c["id"].as_u64().unwrap(), t))
        .collect();
    let (mut got, mut bytes) = (Received::new(), 0u64);
    let end = Instant::now() + WINDOW;
    while Instant::now() < end {
        if let Some(Ws::Binary(frame)) = next(socket)
            && let Some((id, t, payload)) = message_data(&frame)
        {
            bytes += frame.len() as u64;
            let topic = topic_of[&u64::from(id)].clone();
            got.entry(topic).or_default().push((t, payload.to_vec()));
        }
    }
    (got, bytes)
}

fn on<'a>(got: &'a Received, topic: &str) -> &'a [(u64, Vec<u8>)] {
    let m = got.get(topic).map_or(&[][..], Vec::as_slice);
    assert!(!m.is_empty(), "nothing on {topic}: {:?}", got.keys());
    m
}

fn check_clouds(got: &Received) {
    let clouds = on(got, "/spacepose/cloud");
    for (t, payload) in clouds {
        let c = PointCloud::decode(payload.as_slice()).unwrap();
        assert_eq!(c.point_stride, 24, "the documented layout");
        let names: Vec<&str> = c.fields.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["x", "y", "z", "intensity", "t"]);
        assert_eq!(c.data.len() % 24, 0);
        let n = c.data.len() / 24;
        assert!(
            n > 0 && n <= 2_000,
            "{n} points: the default budget is 2000"
        );
        assert_eq!(c.frame_id, "sensor");
        // Logged at the scan end, on the sensor clock.
        assert_eq!(c.timestamp.unwrap().total_nanos(), *t);
        let z = f32::from_le_bytes(c.data[8..12].try_into().unwrap());
        assert!(z.is_finite() && z > 1.0, "a point ahead of the sensor: {z}");
    }
    let header: Value = serde_json::from_slice(&on(got, "/spacepose/cloud/header")[0].1).unwrap();
    assert!(header["point_count"].as_u64().unwrap() <= 2_000, "{header}");
    assert!(
        !got.contains_key("/spacepose/raw_cloud"),
        "raw clouds are off by default"
    );
}

fn check_poses(got: &Received) {
    for topic in ["/spacepose/pose", "/truth"] {
        let mut ahead = 0;
        for (t, payload) in on(got, topic) {
            let p = PoseInFrame::decode(payload.as_slice()).unwrap();
            assert_eq!(p.frame_id, "sensor", "{topic}");
            assert_eq!(p.timestamp.unwrap().total_nanos(), *t, "{topic}");
            let v = p.pose.unwrap().position.unwrap();
            assert!(
                v.x.is_finite() && v.y.is_finite() && v.z.is_finite(),
                "{topic}"
            );
            ahead += usize::from(v.z > 1.0);
        }
        assert!(
            ahead > 0,
            "{topic}: no pose with the target ahead of the sensor"
        );
    }
    for (topic, child) in [
        ("/spacepose/pose/tf", "target"),
        ("/truth/tf", "target_truth"),
    ] {
        let tf = FrameTransform::decode(on(got, topic)[0].1.as_slice()).unwrap();
        assert_eq!(
            (tf.parent_frame_id.as_str(), tf.child_frame_id.as_str()),
            ("sensor", child)
        );
    }
    let tracks: Vec<usize> = on(got, "/spacepose/pose/trajectory")
        .iter()
        .map(|(_, p)| PosesInFrame::decode(p.as_slice()).unwrap().poses.len())
        .collect();
    assert!(tracks.windows(2).all(|w| w[1] >= w[0]), "{tracks:?}");
    assert!(
        tracks.last().is_some_and(|n| (2..=100).contains(n)),
        "{tracks:?}"
    );
    let scene = SceneUpdate::decode(on(got, "/spacepose/scene")[0].1.as_slice()).unwrap();
    let frames: Vec<&str> = scene.entities.iter().map(|e| e.frame_id.as_str()).collect();
    assert_eq!(
        frames,
        ["target", "target_truth"],
        "the model at both poses"
    );
    let status: Value = serde_json::from_slice(&on(got, "/spacepose/pose/estimate")[0].1).unwrap();
    assert!(status["status"].is_string(), "{status}");
}

/// Pids of the recorder instances of the deployment `prefix`.
fn recorders(prefix: &str) -> Vec<u32> {
    processes_mentioning(&format!("--prefix {prefix}"))
        .into_iter()
        .filter(|pid| {
            let cmd = std::fs::read(format!("/proc/{pid}/cmdline")).unwrap_or_default();
            String::from_utf8_lossy(&cmd).contains("spacepose-recorder")
        })
        .collect()
}

#[test]
fn a_foxglove_client_receives_the_running_suite_live() {
    require_suite();
    let dir = scratch_dir("live_view");
    let prefix = unique_prefix("live");
    let _down = DownOnDrop(prefix.clone());
    let deploy = demo_descriptor(&dir, FRAMES, 5.0);
    let view = SocketAddr::from(([127, 0, 0, 1], free_port()));
    let o = spacepose(&[
        "up",
        deploy.to_str().unwrap(),
        "--prefix",
        &prefix,
        "--listen",
        &format!("tcp/127.0.0.1:{}", free_port()),
        "--view",
        &view.to_string(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains(&format!("ws://{view}")),
        "{}",
        text(&o)
    );
    let mut socket = connect(view);
    let wanted = [
        "/spacepose/cloud",
        "/spacepose/pose",
        "/spacepose/pose/trajectory",
        "/truth",
        "/spacepose/scene",
    ];
    let channels = advertised(&mut socket, &wanted);
    for (topic, schema) in [
        ("/spacepose/cloud", "foxglove.PointCloud"),
        ("/spacepose/pose", "foxglove.PoseInFrame"),
        ("/spacepose/pose/trajectory", "foxglove.PosesInFrame"),
        ("/truth", "foxglove.PoseInFrame"),
        ("/spacepose/scene", "foxglove.SceneUpdate"),
        ("/spacepose/pose/estimate", "spacepose.PoseEstimate"),
    ] {
        assert_eq!(channels[topic]["schemaName"], schema, "{topic}");
    }
    let (got, bytes) = collect(&mut socket, &channels);
    let clouds = got.get("/spacepose/cloud").map_or(0, Vec::len);
    let cloud_bytes: usize = got
        .get("/spacepose/cloud")
        .map_or(0, |c| c.iter().map(|(_, p)| p.len()).sum());
    let rate = bytes as f64 / WINDOW.as_secs_f64();
    eprintln!(
        "live link at the default decimation (every channel subscribed, the demo at 5 frames/s): \
         {bytes} B in {:.1} s = {:.1} kB/s, {clouds} clouds ({:.1} kB each), {} poses",
        WINDOW.as_secs_f64(),
        rate / 1e3,
        cloud_bytes as f64 / clouds.max(1) as f64 / 1e3,
        got.get("/spacepose/pose").map_or(0, Vec::len),
    );
    check_clouds(&got);
    check_poses(&got);

    // Loopback only.
    let pids = recorders(&prefix);
    assert_eq!(pids.len(), 1, "one recorder serves the view");
    let listening = listening_tcp(pids[0]);
    assert!(listening.contains(&view), "{listening:?}");
    assert!(
        listening.iter().all(|a| a.ip().is_loopback()),
        "{listening:?}"
    );
    drop(socket);
    let down = spacepose(&["down", "--prefix", &prefix]);
    assert!(down.status.success(), "{}", text(&down));
    assert!(
        TcpStream::connect(view).is_err(),
        "the view stops with the suite"
    );
}

#[test]
fn a_view_beyond_loopback_is_refused_before_anything_starts() {
    require_suite();
    let prefix = unique_prefix("live-no");
    let o = spacepose(&[
        "demo",
        "--frames",
        "3",
        "--prefix",
        &prefix,
        "--view",
        "0.0.0.0:8765",
    ]);
    assert!(!o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("allow_non_loopback"), "{}", text(&o));
    assert!(processes_mentioning(&format!("--prefix {prefix}")).is_empty());
}
