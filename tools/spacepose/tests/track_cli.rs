//! `spacepose track` as a user runs it on a recording: simulated frames on
//! disk, tracked from an acquisition, scored against their `truth.csv`,
//! the same poses twice, and a recording without point times tracked on
//! derived times with a warning.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn spacepose(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_spacepose"))
        .args(args)
        .current_dir(dir)
        .env("SPACEPOSE_CACHE_DIR", dir.join("cache"))
        .output()
        .expect("spawn spacepose")
}

fn ok(out: &Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    String::from_utf8_lossy(&out.stdout).into_owned() + &stderr
}

fn summary(path: PathBuf) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("test fixture"))
        .expect("test fixture")
}

/// A copy of the frames of `from` in `to` as ASCII PCD with `x y z
/// intensity` only (no time field), and the same `truth.csv`.
fn strip_times(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("test fixture");
    for entry in std::fs::read_dir(from).expect("test fixture") {
        let path = entry.expect("test fixture").path();
        let name = path.file_name().expect("test fixture").to_owned();
        if path.extension().is_some_and(|e| e == "pcd") {
            let points = spacepose_geometry::read_cloud(&path).expect("test fixture");
            let mut text = format!(
                "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\n\
                 COUNT 1 1 1 1\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA ascii\n",
                n = points.len()
            );
            for p in &points {
                text += &format!("{} {} {} {}\n", p.x, p.y, p.z, p.intensity);
            }
            std::fs::write(to.join(name), text).expect("test fixture");
        } else if name == "truth.csv" {
            std::fs::copy(&path, to.join(name)).expect("test fixture");
        }
    }
}

#[test]
fn a_recording_is_tracked_from_an_acquisition_the_same_way_twice() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // Development seed 3 (tools/eval/seeds.toml).
    ok(&spacepose(
        dir,
        &["sim", "--frames", "6", "--seed", "3", "--out", "frames"],
    ));
    let args = |out: &str, json: &str| {
        ["track", "--input", "frames", "--out", out, "--json", json].map(str::to_owned)
    };
    let a = args("a.csv", "a.json");
    let log = ok(&spacepose(dir, &a.each_ref().map(String::as_str)));
    let s = summary(dir.join("a.json"));
    assert_eq!(s["frames"], 6, "{log}");
    assert_eq!(s["acquisitions"][0]["verdict"], "correct", "{log}");
    assert_eq!(s["acquisition_counts"]["false_accepts"], 0);
    let errors = &s["errors"];
    assert_eq!(errors["frames_scored"], 5, "{log}");
    assert_eq!(errors["silent_far_off"], 0, "{log}");
    assert!(
        errors["ang_err_deg"]["max"].as_f64().unwrap() < 5.0,
        "{log}"
    );
    assert!(
        errors["pos_err_cm"]["max"].as_f64().unwrap() < 15.0,
        "{log}"
    );
    assert_eq!(s["frames_derived_times"], 0);
    // Deterministic: the same bytes again.
    let b = args("b.csv", "b.json");
    ok(&spacepose(dir, &b.each_ref().map(String::as_str)));
    let (pa, pb) = (
        std::fs::read(dir.join("a.csv")).unwrap(),
        std::fs::read(dir.join("b.csv")).unwrap(),
    );
    assert_eq!(pa, pb, "two runs on the same recording differ");
    assert_eq!(String::from_utf8_lossy(&pa).lines().count(), 7);
    // Recorded as MCAP, then tracked from that recording: the same poses.
    let log = ok(&spacepose(
        dir,
        &["track", "--input", "frames", "--out", "run.mcap"],
    ));
    assert!(log.contains("written to run.mcap"), "{log}");
    // Its raw clouds are chosen without --topic (it holds the cropped ones too).
    let replay = ["track", "--input", "run.mcap", "--out", "replay.csv"];
    ok(&spacepose(dir, &replay));
    let pr = std::fs::read(dir.join("replay.csv")).unwrap();
    assert_eq!(pa, pr, "tracking the MCAP recording gives other poses");

    // No time field: derived times, said in the log, counted, still tracked.
    strip_times(&dir.join("frames"), &dir.join("no-times"));
    let log = ok(&spacepose(
        dir,
        &["track", "--input", "no-times", "--json", "c.json"],
    ));
    assert!(log.contains("no per-point time field"), "{log}");
    let s = summary(dir.join("c.json"));
    assert_eq!(s["frames_derived_times"], 6, "{log}");
    assert_eq!(s["errors"]["silent_far_off"], 0, "{log}");
    let tracked = s["tracking"].as_u64().unwrap() + s["unconfirmed"].as_u64().unwrap();
    assert!(tracked >= 4, "{log}");
    assert!(
        s["tracking"].as_u64().unwrap() >= 1,
        "never confirmed: {log}"
    );
}

#[test]
fn a_given_pose_starts_the_track_and_bad_poses_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    ok(&spacepose(
        dir,
        &["sim", "--frames", "3", "--seed", "3", "--out", "frames"],
    ));
    // The first row of truth.csv, as an operator would type it.
    let truth = std::fs::read_to_string(dir.join("frames/truth.csv")).unwrap();
    let row: Vec<&str> = truth.lines().nth(1).unwrap().split(',').collect();
    let pose = row[4..11].join(",");
    let log = ok(&spacepose(
        dir,
        &[
            "track", "--input", "frames", "--init", &pose, "--json", "g.json",
        ],
    ));
    let s = summary(dir.join("g.json"));
    assert_eq!(s["tracking"], 3, "{log}");
    assert_eq!(s["acquisitions"].as_array().unwrap().len(), 0);
    let bad = spacepose(
        dir,
        &["track", "--input", "frames", "--init", "0,0,15,2,0,0,0"],
    );
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("norm"));
}
