use super::*;
use foxglove::Decode;
use foxglove::messages::{PointCloud, PoseInFrame};
use spacepose_geometry::Point;
use spacepose_messages::{CloudHeader, Health, Name, PoseEstimate, Topic, TruthMsg};

/// (topic, schema name, log time, data) of every message of the file.
fn read(path: &Path) -> Vec<(String, String, u64, Vec<u8>)> {
    let bytes = std::fs::read(path).unwrap();
    mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| {
            let m = m.unwrap();
            let schema = m
                .channel
                .schema
                .as_ref()
                .map_or(String::new(), |s| s.name.clone());
            (m.channel.topic.clone(), schema, m.log_time, m.data.to_vec())
        })
        .collect()
}

fn points(n: usize, t0: f64) -> Vec<Point> {
    (0..n)
        .map(|i| Point::new(i as f32, 1.0, 2.0, 0.5, t0 + 1e-4 * i as f64))
        .collect()
}

fn record_run(path: &Path, options: RecordOptions) -> RecordStats {
    let mut rec = Recorder::create(path, options).unwrap();
    rec.set_target(TargetMesh {
        name: "tri".into(),
        vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        triangles: vec![[0, 1, 2]],
    });
    for k in 0..4u64 {
        let t = 1.0 + 0.1 * k as f64;
        let header = CloudHeader::new(k, t - 0.1, t);
        let pts = points(5, t - 0.1);
        for topic in [Topic::RawCloud, Topic::Cloud] {
            rec.cloud(Cloud {
                topic,
                header: &header,
                points: &pts,
            })
            .unwrap();
        }
        let mut truth = TruthMsg::new();
        (truth.sequence, truth.t_s) = (k, t);
        rec.message(&Message::Truth(truth)).unwrap();
        let mut pose = PoseEstimate::new();
        (pose.sequence, pose.t_s) = (k, t);
        pose.instance = Name::new("tracker").unwrap();
        rec.message(&Message::Pose(pose)).unwrap();
    }
    let name = Name::new("ingest").unwrap();
    rec.message(&Message::Health(Health::new(name, name, 7)))
        .unwrap();
    let configs = BTreeMap::from([("ingest".to_string(), "crop = 1\n".to_string())]);
    rec.metadata("spacepose.configs", configs).unwrap();
    rec.attach("descriptor.toml", "application/toml", b"prefix = \"x\"\n")
        .unwrap();
    rec.close().unwrap()
}

#[test]
fn a_recording_holds_well_known_schemas_at_sensor_times() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    let stats = record_run(&path, RecordOptions::default());
    assert_eq!((stats.clouds, stats.messages), (8, 9));
    let messages = read(&path);
    let on = |topic: &str| messages.iter().filter(|m| m.0 == topic).collect::<Vec<_>>();
    let poses = on("/spacepose/pose");
    assert_eq!(poses.len(), 4);
    assert!(poses.iter().all(|m| m.1 == "foxglove.PoseInFrame"));
    let times: Vec<u64> = poses.iter().map(|m| m.2).collect();
    assert_eq!(
        times,
        [1_000_000_000, 1_100_000_000, 1_200_000_000, 1_300_000_000]
    );
    for (topic, schema, n) in [
        ("/spacepose/raw_cloud", "foxglove.PointCloud", 4),
        ("/spacepose/cloud", "foxglove.PointCloud", 4),
        ("/spacepose/cloud/header", "spacepose.CloudHeader", 4),
        ("/spacepose/pose/tf", "foxglove.FrameTransform", 4),
        ("/spacepose/pose/estimate", "spacepose.PoseEstimate", 4),
        ("/truth", "foxglove.PoseInFrame", 4),
        ("/truth/tf", "foxglove.FrameTransform", 4),
        ("/spacepose/scene", "foxglove.SceneUpdate", 1),
        ("/spacepose/health", "spacepose.Health", 1),
    ] {
        let got = on(topic);
        assert_eq!(got.len(), n, "{topic}");
        assert!(got.iter().all(|m| m.1 == schema), "{topic}");
    }
    // The header beside each cloud, at its log time.
    let cloud = PointCloud::decode(on("/spacepose/raw_cloud")[2].3.as_slice()).unwrap();
    assert_eq!(cloud.data.len(), 5 * 24);
    let header = on("/spacepose/raw_cloud/header")[2];
    let json: serde_json::Value = serde_json::from_slice(&header.3).unwrap();
    assert_eq!(json["sequence"], 2);
    assert_eq!(header.2, on("/spacepose/raw_cloud")[2].2);
    // Heartbeats at the newest sensor time.
    assert_eq!(on("/spacepose/health")[0].2, 1_300_000_000);
    let pose = PoseInFrame::decode(poses[0].3.as_slice()).unwrap();
    assert_eq!(pose.frame_id, "sensor");
    let summary = mcap::Summary::read(&std::fs::read(&path).unwrap())
        .unwrap()
        .unwrap();
    assert_eq!(summary.attachment_indexes.len(), 1);
    assert_eq!(summary.metadata_indexes[0].name, "spacepose.configs");
}

#[test]
fn clouds_are_decimated_by_frame_and_two_recorders_do_not_mix() {
    let dir = tempfile::tempdir().unwrap();
    let options = RecordOptions {
        raw_cloud_every: 2,
        cloud_every: 0,
        ..RecordOptions::default()
    };
    let a = dir.path().join("a.mcap");
    let b = dir.path().join("b.mcap");
    let mut first = Recorder::create(&a, RecordOptions::default()).unwrap();
    let stats = record_run(&b, options);
    first.message(&Message::Pose(PoseEstimate::new())).unwrap();
    first.close().unwrap();
    assert_eq!((stats.clouds, stats.clouds_skipped), (2, 6));
    let raw: Vec<u64> = read(&b)
        .iter()
        .filter(|m| m.0 == "/spacepose/raw_cloud/header")
        .map(|m| {
            serde_json::from_slice::<serde_json::Value>(&m.3).unwrap()["sequence"]
                .as_u64()
                .unwrap()
        })
        .collect();
    assert_eq!(raw, [0, 2]);
    assert!(read(&b).iter().all(|m| m.0 != "/spacepose/cloud"));
    let in_a = read(&a);
    assert_eq!(
        in_a.len(),
        3,
        "{:?}",
        in_a.iter().map(|m| &m.0).collect::<Vec<_>>()
    );
    assert!(Recorder::create(&a, RecordOptions::default()).is_err());
}
