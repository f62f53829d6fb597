//! `spacepose eval tracking --report` as a reviewer runs it: the real
//! binary, a Monte-Carlo over named seeds, one JSON file.

use std::process::Command;

#[test]
fn a_report_runs_every_seed_and_summarises_them() {
    let dir = std::env::temp_dir().join(format!("spacepose-report-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("report.json");
    let out = Command::new(env!("CARGO_BIN_EXE_spacepose"))
        .args([
            "eval",
            "tracking",
            "--scenario",
            "tumbling",
            "--frames",
            "3",
        ])
        .args(["--mode", "deblur", "--seeds", "3,7", "--report"])
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
    assert!(stdout.contains("2 seeds (3,7)"), "{stdout}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    assert_eq!(report["seeds"], serde_json::json!([3, 7]));
    let deblur = &report["modes"]["deblur"];
    let per_seed = deblur["per_seed"].as_array().unwrap();
    assert_eq!(per_seed.len(), 2);
    // Each seed's whole-run max is a real error, and the spread holds it.
    let maxes: Vec<f64> = per_seed
        .iter()
        .map(|s| s["ang_max_deg"].as_f64().unwrap())
        .collect();
    assert!(maxes.iter().all(|m| *m > 0.0 && *m < 10.0), "{maxes:?}");
    let spread = &deblur["stats"]["ang_max_deg"];
    assert_eq!(spread["max"].as_f64().unwrap(), maxes[0].max(maxes[1]));
    // An unknown seed list is refused in one line.
    let bad = Command::new(env!("CARGO_BIN_EXE_spacepose"))
        .args([
            "eval", "tracking", "--frames", "1", "--seeds", "tuned", "--report",
        ])
        .arg(&path)
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--seeds"));
    std::fs::remove_dir_all(&dir).ok();
}
