//! `spacepose sim` as a new user runs it: the real binary, real files.

use std::path::Path;
use std::process::{Command, Output};

fn spacepose(args: &[&str]) -> Output {
    // A mesh given as a target is prepared into a package on first use: keep
    // that cache out of the user's home.
    let cache = std::env::temp_dir().join(format!("spacepose-sim-cli-{}", std::process::id()));
    Command::new(env!("CARGO_BIN_EXE_spacepose"))
        .args(args)
        .env("SPACEPOSE_CACHE_DIR", cache)
        .output()
        .expect("spawn spacepose")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

/// A closed 1 m cube as ASCII STL, in millimetres.
fn write_cube_stl(path: &Path) {
    let v = |x: f64, y: f64, z: f64| [x * 1000.0, y * 1000.0, z * 1000.0];
    let c = [
        v(0., 0., 0.),
        v(1., 0., 0.),
        v(1., 1., 0.),
        v(0., 1., 0.),
        v(0., 0., 1.),
        v(1., 0., 1.),
        v(1., 1., 1.),
        v(0., 1., 1.),
    ];
    let faces = [
        [0, 2, 1],
        [0, 3, 2],
        [4, 5, 6],
        [4, 6, 7],
        [0, 1, 5],
        [0, 5, 4],
        [1, 2, 6],
        [1, 6, 5],
        [2, 3, 7],
        [2, 7, 6],
        [3, 0, 4],
        [3, 4, 7],
    ];
    let mut s = String::from("solid cube\n");
    for f in faces {
        s.push_str("facet normal 0 0 0\nouter loop\n");
        for i in f {
            s.push_str(&format!("vertex {} {} {}\n", c[i][0], c[i][1], c[i][2]));
        }
        s.push_str("endloop\nendfacet\n");
    }
    s.push_str("endsolid cube\n");
    std::fs::write(path, s).expect("writing the cube STL");
}

#[test]
fn writes_frames_and_truth_for_a_builtin_target() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let o = spacepose(&[
        "sim",
        "--target",
        "deos",
        "--scenario",
        "tumbling",
        "--frames",
        "3",
        "--seed",
        "7",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for k in 0..3 {
        let frame = out.join(format!("frame_{k:06}.pcd"));
        let points = spacepose_geometry::read_cloud(&frame).unwrap();
        assert!(points.len() > 1000, "frame {k}: {} points", points.len());
        assert!(points.iter().all(|p| p.is_finite()));
    }
    let truth = std::fs::read_to_string(out.join("truth.csv")).unwrap();
    let lines: Vec<&str> = truth.lines().collect();
    assert_eq!(lines[0], spacepose_eval::truth_csv::HEADER);
    assert_eq!(lines.len(), 4);
    let (frame, t_end, p, _q) = spacepose_eval::truth_csv::parse_row(lines[3]).unwrap();
    assert_eq!(frame, 2);
    assert!((t_end - 3.0).abs() < 1e-9);
    assert!(
        (nalgebra::Vector3::from(p).norm() - 15.0).abs() < 0.5,
        "tumbling starts at 15 m"
    );
    // The same seed gives the same frames.
    let again = dir.path().join("again");
    let o = spacepose(&[
        "sim",
        "--frames",
        "1",
        "--seed",
        "7",
        "--out",
        again.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    assert_eq!(
        std::fs::read(out.join("frame_000000.pcd")).unwrap(),
        std::fs::read(again.join("frame_000000.pcd")).unwrap()
    );
}

#[test]
fn simulates_a_mesh_file_with_scale() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("cube.stl");
    write_cube_stl(&mesh);
    let out = dir.path().join("cube");
    let o = spacepose(&[
        "sim",
        "--target",
        mesh.to_str().unwrap(),
        "--scale",
        "0.002",
        "--scenario",
        "random",
        "--range",
        "8",
        "--frames",
        "2",
        "--out",
        out.to_str().unwrap(),
        "--format",
        "ply",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let points = spacepose_geometry::read_cloud(out.join("frame_000000.ply")).unwrap();
    assert!(!points.is_empty());
    // A 2 m cube (1000 mm × 0.002) centred 8 m away: every return within its reach.
    for p in &points {
        let r = p.position().norm();
        assert!(r > 8.0 - 1.8 && r < 8.0 + 1.8, "range {r}");
    }
}

#[test]
fn bad_arguments_give_one_line_errors_and_a_failure_status() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x");
    let missing = dir.path().join("missing.stl");
    let garbage = dir.path().join("garbage.stl");
    std::fs::write(&garbage, b"solid x\nthis is not an stl file\n").unwrap();
    let cases: Vec<Vec<&str>> = vec![
        vec!["sim", "--target", "hubble", "--out", out.to_str().unwrap()],
        vec![
            "sim",
            "--target",
            missing.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        vec![
            "sim",
            "--target",
            garbage.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        vec!["sim", "--frames", "0", "--out", out.to_str().unwrap()],
        vec!["sim", "--frames", "-3", "--out", out.to_str().unwrap()],
        vec![
            "sim",
            "--scale",
            "-1",
            "--target",
            garbage.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    ];
    for args in cases {
        let o = spacepose(&args);
        assert!(!o.status.success(), "{args:?} should fail");
        let err = stderr(&o);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
        assert!(lines[0].starts_with("error"), "{args:?}: {err}");
        // Our own errors are one line; clap adds a usage hint after its own.
        if !err.contains("Usage") && !err.contains("--help") {
            assert_eq!(lines.len(), 1, "{args:?}: {err}");
        }
    }
}
