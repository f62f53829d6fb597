//! `spacepose replay RUN.mcap`: a recorded demo fed back through the suite.
//! Every recorded frame goes back in; when the replay's acquisitions land
//! on the recorded frames and no frame is dropped, every pose is the
//! recorded pose bit for bit, with the recorded status unless init's
//! confirmation landed on another frame (`unconfirmed` against `tracking`
//! only); every difference is named with its reason. Offline tracking of
//! the same file is bit-identical run to run
//! (`tools/spacepose/tests/track_cli.rs`).
#![allow(clippy::unwrap_used)] // test helpers

use serde_json::Value;
use spacepose_e2e::*;

const FRAMES: u64 = 16;

#[test]
fn a_replayed_demo_gives_the_recorded_poses_or_says_why_not() {
    require_suite();
    let dir = scratch_dir("replay");
    let run = dir.join("run.mcap");
    let prefix = unique_prefix("replay-rec");
    let _down = DownOnDrop(prefix.clone());
    let o = spacepose(&[
        "demo",
        "--frames",
        &FRAMES.to_string(),
        "--prefix",
        &prefix,
        "--listen",
        &format!("tcp/127.0.0.1:{}", free_port()),
        "--record",
        run.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));

    let prefix = unique_prefix("replay");
    let _down_replay = DownOnDrop(prefix.clone());
    let json = dir.join("compare.json");
    let o = spacepose(&[
        "replay",
        run.to_str().unwrap(),
        "--prefix",
        &prefix,
        "--listen",
        &format!("tcp/127.0.0.1:{}", free_port()),
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(processes_mentioning(&format!("--prefix {prefix}")).is_empty());
    let c: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let n = |k: &str| c[k].as_u64().unwrap();
    let f = |k: &str| c[k].as_f64().unwrap();
    let reasons = c["reasons"].as_array().unwrap();
    assert_eq!(n("recorded_poses"), FRAMES, "{c}");
    assert!(n("matched") + 2 >= FRAMES, "frames not replayed: {c}");
    let same_frames = c["recorded_acquisitions"] == c["replayed_acquisitions"]
        && n("missing_in_replay") == 0
        && n("extra_in_replay") == 0;
    // Where init's confirmation lands changes statuses between
    // `unconfirmed` and `tracking` only, never a pose.
    let same_confirmations = c["recorded_confirmations"] == c["replayed_confirmations"];
    if same_frames {
        assert!(
            f("max_angle_deg") < 1e-3 && f("max_position_mm") < 1e-3,
            "{c}"
        );
        for d in c["status_differences"].as_array().unwrap() {
            let pair = (d[1].as_str().unwrap(), d[2].as_str().unwrap());
            assert!(
                !same_confirmations
                    && matches!(
                        pair,
                        ("unconfirmed", "tracking") | ("tracking", "unconfirmed")
                    ),
                "{c}"
            );
        }
    }
    if !(same_frames && same_confirmations) {
        assert!(!reasons.is_empty(), "a difference without a reason: {c}");
    }
    let reproduced = n("identical") == FRAMES && n("extra_in_replay") == 0;
    assert_eq!(reasons.is_empty(), reproduced, "{c}");
    assert!(text(&o).contains(if reproduced {
        "reproduced: yes"
    } else {
        "reproduced: no"
    }));
}

#[test]
fn a_file_that_is_no_spacepose_recording_is_a_clear_error() {
    let dir = scratch_dir("replay-bad");
    let bad = dir.join("bad.mcap");
    std::fs::write(&bad, b"\x89MCAP0\r\nnot really").unwrap();
    let o = spacepose(&["replay", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("bad.mcap"), "{}", text(&o));
}
