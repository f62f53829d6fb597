//! `spacepose eval tracking --init acquire`: the deployed path from a
//! no-truth start, every acquisition scored against the truth.

use std::process::Command;

#[test]
fn eval_tracking_acquires_without_truth_and_scores_the_acquisition() {
    let dir = std::env::temp_dir().join(format!("spacepose-acquire-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("run.json");
    // Development seed 3 (tools/eval/seeds.toml).
    let out = Command::new(env!("CARGO_BIN_EXE_spacepose"))
        .args([
            "eval",
            "tracking",
            "--scenario",
            "tumbling",
            "--frames",
            "6",
        ])
        .args([
            "--seed", "3", "--mode", "deblur", "--init", "acquire", "--json",
        ])
        .arg(&path)
        .env("SPACEPOSE_CACHE_DIR", dir.join("cache"))
        .output()
        .expect("spawn spacepose");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let deblur = &report["modes"]["deblur"];
    let series = deblur["series"].as_array().unwrap();
    // No truth: the first frame has no pose yet; init acquires on it.
    assert_eq!(series[0]["status"], "lost", "{stdout}");
    let acquisition = &series[0]["acquisition"];
    assert_eq!(acquisition["accepted"], true, "{stdout}");
    assert_eq!(acquisition["verdict"], "correct", "{stdout}");
    assert!(acquisition["ang_err_deg"].as_f64().unwrap() < 10.0);
    // Tracked from the next frame on, within the far-off bound:
    // `unconfirmed` until init's second look agrees, then `tracking`.
    assert_eq!(series.last().unwrap()["status"], "tracking", "{stdout}");
    for r in &series[1..] {
        let status = r["status"].as_str().unwrap();
        assert!(["tracking", "unconfirmed"].contains(&status), "{stdout}");
        assert!(r["ang_err_deg"].as_f64().unwrap() < 10.0, "{stdout}");
    }
    assert_eq!(deblur["acquisitions"]["correct"], 1);
    assert_eq!(deblur["acquisitions"]["false_accepts"], 0);
    assert_eq!(deblur["silent_frames"], 0);
    assert!(stdout.contains("acquisitions: 1 correct"), "{stdout}");
    std::fs::remove_dir_all(&dir).ok();
}
