//! `spacepose demo --record`: the run's MCAP file, read by the Python
//! `mcap` reader (a third party), has Foxglove schema names on its
//! channels, one pose message per pose the demo published, truth for every
//! frame, the raw clouds in the documented layout, and the descriptor and
//! service configurations. PyPI is reachable where the tests run, so a
//! Python reader that cannot be installed fails the test.
#![allow(clippy::unwrap_used)] // test helpers

use serde_json::Value;
use spacepose_e2e::*;

const FRAMES: u64 = 30;

/// The pinned Python reader: `mcap` and its protobuf decoder.
fn python_mcap() -> std::path::PathBuf {
    python_with(
        "mcap",
        &[
            "mcap==1.6.0",
            "mcap-protobuf-support==0.6.0",
            "protobuf==7.36.2",
        ],
        "import mcap, mcap_protobuf",
    )
    .unwrap_or_else(|why| panic!("the Python mcap reader: {why}"))
}

fn channel<'a>(got: &'a Value, topic: &str) -> &'a Value {
    let c = &got["channels"][topic];
    assert!(c.is_object(), "no channel {topic}: {}", got["channels"]);
    c
}

#[test]
fn a_recorded_demo_is_read_by_the_python_mcap_reader() {
    require_suite();
    let python = python_mcap();
    let dir = scratch_dir("record");
    let prefix = unique_prefix("record");
    let _down = DownOnDrop(prefix.clone());
    let (json, run) = (dir.join("demo.json"), dir.join("run.mcap"));
    let o = spacepose(&[
        "demo",
        "--frames",
        &FRAMES.to_string(),
        "--prefix",
        &prefix,
        "--listen",
        &format!("tcp/127.0.0.1:{}", free_port()),
        "--json",
        json.to_str().unwrap(),
        "--record",
        run.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let s: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert!(processes_mentioning(&format!("--prefix {prefix}")).is_empty());

    let read = std::process::Command::new(&python)
        .arg(repo_root().join("tests/python/read_recording.py"))
        .arg(&run)
        .output()
        .unwrap();
    assert!(read.status.success(), "{}", text(&read));
    let got: Value = serde_json::from_slice(&read.stdout).unwrap();

    for (topic, schema) in [
        ("/spacepose/raw_cloud", "foxglove.PointCloud"),
        ("/spacepose/cloud", "foxglove.PointCloud"),
        ("/spacepose/pose", "foxglove.PoseInFrame"),
        ("/spacepose/pose/tf", "foxglove.FrameTransform"),
        ("/truth", "foxglove.PoseInFrame"),
        ("/truth/tf", "foxglove.FrameTransform"),
        ("/spacepose/scene", "foxglove.SceneUpdate"),
        ("/spacepose/pose/estimate", "spacepose.PoseEstimate"),
        ("/spacepose/filter_state", "spacepose.FilterState"),
        ("/spacepose/acquisition", "spacepose.Acquisition"),
        ("/spacepose/health", "spacepose.Health"),
    ] {
        assert_eq!(channel(&got, topic)["schema"], schema, "{topic}");
    }
    assert_eq!(
        channel(&got, "/spacepose/pose")["schema_encoding"],
        "protobuf"
    );
    assert_eq!(
        channel(&got, "/spacepose/health")["message_encoding"],
        "json"
    );

    // One pose message per pose the demo published, for the same frames.
    let published = s["poses_published"].as_u64().unwrap();
    assert_eq!(published, FRAMES, "{s}");
    assert_eq!(channel(&got, "/spacepose/pose")["count"], published);
    assert_eq!(got["poses_decoded"], published);
    let mut recorded: Vec<u64> = got["pose_sequences"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect();
    recorded.sort_unstable();
    let mut scored: Vec<u64> = s["series"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["sequence"].as_u64().unwrap())
        .collect();
    scored.sort_unstable();
    assert_eq!(recorded, scored);
    assert_eq!(got["pose_frames"], serde_json::json!(["sensor"]));
    assert_eq!(got["log_time_sorted"], true);

    // Truth for every frame; the clouds in the layout replay depends on.
    assert_eq!(channel(&got, "/truth")["count"], s["frames_published"]);
    assert_eq!(channel(&got, "/spacepose/raw_cloud")["count"], FRAMES);
    let layout = &got["cloud_layout"];
    assert_eq!(
        layout["fields"],
        serde_json::json!([
            ["x", 0, 7],
            ["y", 4, 7],
            ["z", 8, 7],
            ["intensity", 12, 7],
            ["t", 16, 8]
        ])
    );
    assert_eq!(layout["stride"], 24);
    assert!(layout["points"].as_u64().unwrap() > 100, "{layout}");
    assert_eq!(got["cloud_t_matches"], true);
    assert_eq!(channel(&got, "/spacepose/scene")["count"], 1);

    // The descriptor and every service's configuration.
    assert_eq!(got["attachments"], serde_json::json!(["descriptor.toml"]));
    let metadata: Vec<&str> = got["metadata"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m.as_str().unwrap())
        .collect();
    for name in [
        "lidar-sim",
        "ingest",
        "tracker",
        "filter",
        "telemetry",
        "init",
    ] {
        let record = format!("spacepose.config.{name}");
        assert!(metadata.contains(&record.as_str()), "{metadata:?}");
    }
    assert!(metadata.contains(&"spacepose.run"));
}
