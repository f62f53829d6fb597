//! Faults and swaps through the real binaries (issue 7), on
//! `deploy/redundant.toml` (tracker-a primary, tracker-b standby), each
//! test with its own prefix and zenoh port:
//! - `kill -9` of the primary tracker: no frame without a pose;
//! - `kill -9` of every other service in turn: the suite recovers, the run
//!   completes;
//! - SIGSTOP of the primary tracker: the filter takes the standby's pose at
//!   the frame deadline, the supervisor detects the hang and restarts it;
//! - a swap of the primary tracker during the run: no frame without a pose.
//!
//! The figures (detection, restart, takeover, swap times) are printed.
//! The tests run one at a time: several suites at once on two cores would
//! measure the machine, not the suite.
#![allow(clippy::unwrap_used)] // test helpers

use serde_json::Value;
use spacepose_e2e::*;
use std::sync::Mutex;

static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// The filter's frame deadline in deploy/redundant.toml (ms).
const FRAME_DEADLINE_MS: f64 = 100.0;

/// Runs `spacepose demo` on deploy/redundant.toml with `extra` arguments;
/// returns the JSON summary and the output.
fn redundant_demo(tag: &str, frames: u64, extra: &[&str]) -> (Value, String) {
    require_suite();
    let dir = scratch_dir(tag);
    let prefix = unique_prefix(tag);
    let _down = DownOnDrop(prefix.clone());
    let json = dir.join("demo.json");
    let deploy = repo_root().join("deploy/redundant.toml");
    let listen = format!("tcp/127.0.0.1:{}", free_port());
    let frames = frames.to_string();
    let mut args = vec![
        "demo",
        "--deploy",
        deploy.to_str().unwrap(),
        "--frames",
        &frames,
        "--warmup",
        "3",
        "--linger-s",
        "3",
        "--prefix",
        &prefix,
        "--listen",
        &listen,
        "--json",
        json.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let out = spacepose(&args);
    let t = text(&out);
    assert!(out.status.success(), "{t}");
    // Nothing of the suite is left, and no shared memory of its prefix.
    assert!(!state_file(&prefix).exists(), "{t}");
    assert!(
        processes_mentioning(&format!("--prefix {prefix}")).is_empty(),
        "{t}"
    );
    let shm: Vec<String> = std::fs::read_dir("/dev/shm")
        .unwrap()
        .flatten()
        .filter_map(|e| e.file_name().to_str().map(str::to_string))
        .filter(|n| n.starts_with(&format!("sp_{prefix}_")))
        .collect();
    assert!(shm.is_empty(), "left in /dev/shm: {shm:?}");
    let s: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    (s, t)
}

fn figures(s: &Value) -> String {
    let mut lines = Vec::new();
    for c in s["chaos"].as_array().unwrap() {
        lines.push(format!(
            "{} {}: detected by {} after {} ms, restarted (first heartbeat) after {} ms, takeover {} ms",
            c["action"], c["instance"], c["detected_by"], c["detection_ms"], c["restart_ms"], c["takeover_ms"]
        ));
    }
    lines.push(format!(
        "missed_poses {}, unfused tracked frames {}, fusion latency ms {}",
        s["missed_poses"], s["unfused_tracking_frames"], s["fusion_latency_ms"]
    ));
    lines.join("\n")
}

fn ms(v: &Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

#[test]
fn killing_the_primary_tracker_misses_no_pose() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let (s, t) = redundant_demo("killprim", 14, &["--chaos", "kill:tracker-a@4"]);
    println!("{}", figures(&s));
    assert_eq!(s["missed_poses"], 0, "{t}");
    assert_eq!(s["unfused_tracking_frames"], 0, "{t}");
    let c = &s["chaos"][0];
    assert_eq!(c["injected"], true, "{t}");
    assert!(
        c["detected_by"].as_str().unwrap().starts_with("exit"),
        "{t}"
    );
    // Aim 100 ms; the bound leaves room for a loaded machine.
    assert!(ms(&c["detection_ms"]) < 300.0, "{t}");
    // The standby's pose is fused at the frame deadline.
    assert!(ms(&c["takeover_ms"]) < FRAME_DEADLINE_MS + 80.0, "{t}");
    assert_eq!(c["decision"], "restart", "{t}");
}

#[test]
fn killing_each_other_service_in_turn_the_suite_recovers() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let (s, t) = redundant_demo(
        "killall",
        24,
        &[
            // The tracker first: its restart loads the NDT map (seconds).
            "--chaos",
            "kill:tracker-b@2",
            "--chaos",
            "kill:ingest@6",
            "--chaos",
            "kill:filter@10",
            "--chaos",
            "kill:telemetry@13",
            // Early too: a new init service loads the CNN and builds the
            // template matcher's models before its first heartbeat.
            "--chaos",
            "kill:init@4",
        ],
    );
    println!("{}", figures(&s));
    assert_eq!(s["frames_published"], 24, "{t}");
    for c in s["chaos"].as_array().unwrap() {
        assert_eq!(c["injected"], true, "{t}");
        assert_eq!(c["decision"], "restart", "{c} {t}");
        assert!(ms(&c["detection_ms"]) < 300.0, "{c}");
        assert!(
            ms(&c["restart_ms"]).is_finite(),
            "restarted and healthy: {c}\n{t}"
        );
        assert_eq!(s["restarts"][c["instance"].as_str().unwrap()], 1, "{t}");
    }
    // Only the frames ingest had no process for can miss a pose.
    assert!(s["missed_poses"].as_u64().unwrap() <= 3, "{t}");
    // The last frames, after every restart, have poses.
    let series = s["series"].as_array().unwrap();
    let last: Vec<u64> = series
        .iter()
        .map(|f| f["sequence"].as_u64().unwrap())
        .filter(|q| *q >= 20)
        .collect();
    assert_eq!(last, vec![20, 21, 22, 23], "{t}");
}

#[test]
fn freezing_the_primary_tracker_hands_over_to_the_standby() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let (s, t) = redundant_demo("stopprim", 14, &["--chaos", "stop:tracker-a@4"]);
    println!("{}", figures(&s));
    assert_eq!(s["missed_poses"], 0, "{t}");
    assert_eq!(s["unfused_tracking_frames"], 0, "{t}");
    let c = &s["chaos"][0];
    // Within one frame deadline the filter takes the standby's pose ...
    assert!(ms(&c["takeover_ms"]) < FRAME_DEADLINE_MS + 80.0, "{t}");
    // ... and the supervisor sees the missing heartbeats (hang_timeout_ms
    // 500), kills and restarts the frozen tracker.
    assert_eq!(c["detected_by"], "hung", "{t}");
    assert!(ms(&c["detection_ms"]) < 1000.0, "{t}");
    assert_eq!(c["decision"], "restart", "{t}");
}

#[test]
fn swapping_the_tracker_during_a_run_misses_no_pose() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let (s, t) = redundant_demo("swap", 30, &["--swap", "ct-ndt@3"]);
    println!("{}", figures(&s));
    let w = &s["swap"];
    println!("swap: {w}");
    assert!(w["error"].is_null(), "{t}");
    assert_eq!(
        (w["old"].as_str(), w["new"].as_str()),
        (Some("tracker-a"), Some("tracker-s1"))
    );
    assert!(ms(&w["total_ms"]).is_finite(), "{t}");
    assert_eq!(s["missed_poses"], 0, "{t}");
    assert_eq!(s["unfused_tracking_frames"], 0, "{t}");
    // The old primary is gone, the new one ran to the end.
    assert!(s["restarts"].get("tracker-a").is_none(), "{t}");
    assert_eq!(s["restarts"]["tracker-s1"], 0, "{t}");
}
