//! `spacepose demo` over the real binaries: a pose for every frame, errors
//! within the tracking goals, and every pose received on the ground over
//! zenoh by a separate `spacepose ground` process and by a Python
//! `eclipse-zenoh` client (skipped, visibly, where it cannot be installed).
#![allow(clippy::unwrap_used)] // test helpers

use serde_json::Value;
use spacepose_e2e::*;
use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const FRAMES: u64 = 20;
const WARMUP: u64 = 10;

/// Starts a listener process and waits for its first stdout line (it is
/// subscribed by then).
fn start_listener(cmd: &mut Command, what: &str) -> (Child, BufReader<std::process::ChildStdout>) {
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("starting {what}: {e}"));
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    out.read_line(&mut line).unwrap();
    assert!(!line.is_empty(), "{what} ended before subscribing");
    (child, out)
}

fn finish(mut child: Child, mut out: BufReader<std::process::ChildStdout>, what: &str) -> String {
    let deadline = Instant::now() + Duration::from_secs(60);
    while child.try_wait().unwrap().is_none() {
        assert!(Instant::now() < deadline, "{what} did not finish");
        std::thread::sleep(Duration::from_millis(50));
    }
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut out, &mut rest).unwrap();
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    let status = child.wait().unwrap();
    assert!(status.success(), "{what} failed ({status}):\n{rest}\n{err}");
    rest
}

#[test]
fn demo_publishes_a_pose_for_every_frame_and_the_ground_receives_them() {
    let spacepose_bin = require_suite();
    let dir = scratch_dir("demo");
    let prefix = unique_prefix("demo");
    let _down = DownOnDrop(prefix.clone());
    let suite_port = free_port();
    let ground_port = free_port();
    let record = dir.join("ground.jsonl");

    // The ground tool listens; the suite's telemetry connects to it.
    let ground_ep = format!("tcp/127.0.0.1:{ground_port}");
    let (ground, ground_out) = start_listener(
        Command::new(&spacepose_bin).args([
            "ground",
            "--listen",
            &ground_ep,
            "--prefix",
            &prefix,
            "--count",
            &FRAMES.to_string(),
            "--duration",
            "150",
            "--refresh-s",
            "0",
            "--record",
            record.to_str().unwrap(),
        ]),
        "spacepose ground",
    );

    let python = match python_with_zenoh() {
        Ok(py) => Some(py),
        Err(why) => {
            eprintln!("SKIPPED: the Python eclipse-zenoh client check ({why})");
            None
        }
    };
    let py_ep = format!("tcp/127.0.0.1:{}", free_port());
    let py_listener = python.as_ref().map(|py| {
        start_listener(
            Command::new(py).args([
                repo_root()
                    .join("tests/python/listen_poses.py")
                    .to_str()
                    .unwrap(),
                &py_ep,
                &prefix,
                &FRAMES.to_string(),
                "150",
            ]),
            "the Python zenoh client",
        )
    });

    let json = dir.join("demo.json");
    let deploy = repo_root().join("deploy/demo.toml");
    let mut args = vec![
        "demo".to_string(),
        "--deploy".into(),
        deploy.display().to_string(),
        "--frames".into(),
        FRAMES.to_string(),
        "--warmup".into(),
        WARMUP.to_string(),
        "--prefix".into(),
        prefix.clone(),
        "--listen".into(),
        format!("tcp/127.0.0.1:{suite_port}"),
        "--connect".into(),
        ground_ep.clone(),
        "--json".into(),
        json.display().to_string(),
    ];
    if python.is_some() {
        args.extend(["--connect".to_string(), py_ep.clone()]);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let demo = spacepose(&args);
    let demo_text = text(&demo);
    assert!(demo.status.success(), "{demo_text}");
    println!("{demo_text}");

    // The demo's own scoring: a pose for every frame (accuracy: the tests below).
    let s: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(s["frames"], FRAMES, "{s}");
    assert_eq!(s["poses_published"], FRAMES, "{demo_text}");
    assert_eq!(s["missed_poses"], 0, "{demo_text}");
    for k in ["mean", "median", "max"] {
        assert!(s["latency_ms"][k].as_f64().is_some_and(|v| v > 0.0), "{s}");
    }
    assert!(demo_text.contains("ang mean"), "{demo_text}");

    // Nothing of the suite is left.
    assert!(!state_file(&prefix).exists());
    assert!(processes_mentioning(&format!("--prefix {prefix}")).is_empty());

    // The ground tool received every pose.
    finish(ground, ground_out, "spacepose ground");
    let lines = std::fs::read_to_string(&record).unwrap();
    let mut seqs: Vec<u64> = lines
        .lines()
        .map(|l| serde_json::from_str::<Value>(l).unwrap())
        .filter(|v| v["key"].as_str().unwrap().ends_with("/telemetry/pose"))
        .map(|v| v["payload"]["sequence"].as_u64().unwrap())
        .collect();
    seqs.sort_unstable();
    seqs.dedup();
    assert_eq!(seqs, (0..FRAMES).collect::<Vec<_>>(), "ground poses");

    // And so did Python.
    if let Some((child, out)) = py_listener {
        let rest = finish(child, out, "the Python zenoh client");
        let got: Value = serde_json::from_str(rest.trim()).unwrap();
        let mut seqs: Vec<u64> = got["sequences"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap())
            .collect();
        seqs.sort_unstable();
        seqs.dedup();
        assert_eq!(seqs, (0..FRAMES).collect::<Vec<_>>(), "python poses");
        println!("python eclipse-zenoh client received {} poses", seqs.len());
    }
}

/// Runs `spacepose demo` on `deploy` and returns its JSON summary.
fn demo_summary(tag: &str, deploy: &std::path::Path) -> (Value, String) {
    demo_summary_with(tag, deploy, &[])
}

/// [`demo_summary`] with more `spacepose demo` arguments.
fn demo_summary_with(tag: &str, deploy: &std::path::Path, extra: &[&str]) -> (Value, String) {
    require_suite();
    let dir = scratch_dir(tag);
    let prefix = unique_prefix(tag);
    let _down = DownOnDrop(prefix.clone());
    let json = dir.join("demo.json");
    let o = spacepose(
        &[
            "demo",
            "--deploy",
            deploy.to_str().unwrap(),
            "--frames",
            &FRAMES.to_string(),
            "--warmup",
            &WARMUP.to_string(),
            "--prefix",
            &prefix,
            "--listen",
            &format!("tcp/127.0.0.1:{}", free_port()),
            "--json",
            json.to_str().unwrap(),
        ]
        .into_iter()
        .chain(extra.iter().copied())
        .collect::<Vec<_>>(),
    );
    let all = text(&o);
    assert!(o.status.success(), "{all}");
    println!("{all}");
    (
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap(),
        all,
    )
}

/// The tracking goal of the tumbling case (≤ 3° once the filter has
/// converged), checked through the real processes.
fn assert_tracking_goals(s: &Value, all: &str) {
    assert_eq!(s["missed_poses"], 0, "{all}");
    let conv_max = s["ang_err_deg_converged"]["max"].as_f64().unwrap();
    assert!(
        conv_max <= 3.0,
        "max angular error after warm-up {conv_max}°\n{all}"
    );
    let pos_mean = s["pos_err_cm"]["mean"].as_f64().unwrap();
    assert!(pos_mean <= 5.0, "mean position error {pos_mean} cm\n{all}");
}

/// The tracking goals through ingest, tracker and filter processes, on the
/// shipped demo (no facility background, the conditions of the tracking
/// issue's goals).
#[test]
fn demo_without_clutter_meets_the_tracking_goals() {
    let (s, all) = demo_summary("clean", &repo_root().join("deploy/demo.toml"));
    assert_tracking_goals(&s, &all);
}

/// A target that is neither built in nor has a CNN, given as a mesh path
/// (deploy/examples/demo-own-target.toml, the probe test mesh): every
/// service prepares it into the package cache, init acquires it by
/// template matching alone, and the suite tracks it. The bound is the
/// probe's own: its attitude is weakly constrained (1.3 m, few features),
/// and started from the truth on blind seeds its deblur track reaches
/// 5.4° p95 and 7.1° max (docs/design/target-packages.md).
#[test]
fn demo_on_an_own_mesh_acquires_by_template_matching_and_tracks() {
    let deploy = repo_root().join("deploy/examples/demo-own-target.toml");
    let (s, all) = demo_summary("own", &deploy);
    assert_eq!(s["missed_poses"], 0, "{all}");
    let conv_max = s["ang_err_deg_converged"]["max"].as_f64().unwrap();
    assert!(
        conv_max <= 10.0,
        "max angular error after warm-up {conv_max}°\n{all}"
    );
    let pos_mean = s["pos_err_cm"]["mean"].as_f64().unwrap();
    assert!(pos_mean <= 5.0, "mean position error {pos_mean} cm\n{all}");
}

/// `spacepose demo --target zoo:5`: the main job on a generated design
/// (development design 5, 9 m across, no symmetry, seed 7) with no
/// descriptor edited: acquired by template matching, whose attempts take
/// longer than the demo's 0.2 s frames (the tracker catches the late
/// acquisition up), then tracked. On this run: a pose from frame 2, 3.4°
/// max after warm-up; the bound leaves room for the machine's timing.
#[test]
fn demo_on_a_generated_target_needs_no_descriptor() {
    let deploy = repo_root().join("deploy/demo.toml");
    let extra = ["--target", "zoo:5", "--seed", "7"];
    let (s, all) = demo_summary_with("zoo", &deploy, &extra);
    assert_eq!(s["missed_poses"], 0, "{all}");
    let series = s["series"].as_array().unwrap();
    let first = series.iter().position(|f| f["status"] != "lost");
    assert!(
        first.is_some_and(|k| k <= 4),
        "first pose at {first:?}\n{all}"
    );
    let conv_max = s["ang_err_deg_converged"]["max"].as_f64().unwrap();
    assert!(
        conv_max <= 5.0,
        "max angular error after warm-up {conv_max}°\n{all}"
    );
}

/// The same goals with the test-facility background that ingest must crop
/// (deploy/examples/demo-clutter.toml): init acquires on ingest's detection
/// crop, which keeps the top of the robot arm, and its pose can be 10-25°
/// off. The tracker's first registration then restarts the filter at its
/// own pose (docs/design/acquisition-seed.md), so that error does not
/// become a rate; before that rule this run published 8-10 of 20 frames
/// `tracking`, the others degraded or lost.
#[test]
fn demo_with_clutter_meets_the_tracking_goals() {
    let (s, all) = demo_summary(
        "clutter",
        &repo_root().join("deploy/examples/demo-clutter.toml"),
    );
    assert_tracking_goals(&s, &all);
}
