//! A ROS 2 bag written by a third-party library (`rosbags`, pinned, from
//! PyPI) from simulated frames is read by spacepose-input with the same
//! points and per-point times as the PCD directory it was made from: the
//! float64 `t` field bit-exact, Livox-style `offset_time` (u32 ns relative
//! to the stamp) to the nanosecond, and without a time field derived over
//! the scan and flagged. PyPI is reachable where the tests run, so a
//! library that cannot be installed fails the test.
#![allow(clippy::unwrap_used)] // test helpers

use spacepose_e2e::{python_with, repo_root};
use spacepose_eval::sim::{FormatArg, PatternArg, SimArgs, run};
use spacepose_input::{InputFrame, InputOptions, PointTimes, ScanTimeSource, TruthTimes, open};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

const FRAMES: u64 = 3;

/// The pinned writer (and numpy, which it needs).
fn python_rosbags() -> &'static Path {
    static PYTHON: OnceLock<PathBuf> = OnceLock::new();
    PYTHON.get_or_init(|| {
        python_with(
            "rosbags",
            &["rosbags==0.11.9", "numpy==2.4.6"],
            "import rosbags.rosbag2, numpy",
        )
        .unwrap_or_else(|why| panic!("the Python rosbags writer: {why}"))
    })
}

/// Simulated frames (`spacepose sim`: binary PCD with absolute f64 `t`, and truth.csv).
fn frames_dir() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        run(&SimArgs {
            target: "deos".into(),
            scale: 1.0,
            scenario: spacepose_scenario::ScenarioKind::Tumbling,
            frames: FRAMES,
            seed: 26,
            out: dir.path().to_owned(),
            compression: 1.0,
            range: 20.0,
            pattern: PatternArg::Rosette,
            integration_time: None,
            clutter: false,
            ideal: false,
            format: FormatArg::Pcd,
        })
        .unwrap();
        dir
    })
    .path()
}

/// Writes the bag with `--time time_mode` and reads it back.
fn bag_frames(time_mode: &str, options: &InputOptions) -> Vec<InputFrame> {
    let out = tempfile::tempdir().unwrap();
    let bag = out.path().join("bag");
    let o = Command::new(python_rosbags())
        .arg(repo_root().join("tests/python/write_ros2_bag.py"))
        .arg(frames_dir())
        .arg(&bag)
        .args(["--time", time_mode])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut rec = open(&bag, options).unwrap();
    assert_eq!(rec.len_hint(), Some(FRAMES as usize), "{}", rec.describe());
    rec.frames().map(Result::unwrap).collect()
}

fn pcd_frames() -> Vec<InputFrame> {
    let mut rec = open(frames_dir(), &InputOptions::default()).unwrap();
    rec.frames().map(Result::unwrap).collect()
}

/// Positions and intensities bit-exact, in the same order.
fn assert_same_points(bag: &InputFrame, pcd: &InputFrame) {
    assert_eq!(bag.points.len(), pcd.points.len(), "frame {}", pcd.index);
    assert!(
        pcd.points.len() > 1000,
        "frame {}: {} points",
        pcd.index,
        pcd.points.len()
    );
    for (i, (b, p)) in bag.points.iter().zip(&pcd.points).enumerate() {
        let bits = |q: &spacepose_geometry::Point| {
            (
                q.x.to_bits(),
                q.y.to_bits(),
                q.z.to_bits(),
                q.intensity.to_bits(),
            )
        };
        assert_eq!(bits(b), bits(p), "frame {} point {i}", pcd.index);
    }
}

#[test]
fn float64_t_reads_back_bit_exact() {
    let (bag, pcd) = (bag_frames("t", &InputOptions::default()), pcd_frames());
    assert_eq!(bag.len(), pcd.len());
    for (b, p) in bag.iter().zip(&pcd) {
        assert_same_points(b, p);
        assert!(matches!(&b.point_times, PointTimes::Field(f) if f.name == "t"));
        for (q, r) in b.points.iter().zip(&p.points) {
            assert_eq!(q.t.to_bits(), r.t.to_bits(), "frame {}", p.index);
        }
        assert_eq!(b.scan_time_source, ScanTimeSource::PointTimes);
        assert_eq!(b.frame_id, "lidar");
    }
}

#[test]
fn livox_offset_time_reads_back_to_the_nanosecond() {
    let (bag, pcd) = (
        bag_frames("offset_time", &InputOptions::default()),
        pcd_frames(),
    );
    assert_eq!(bag.len(), pcd.len());
    for (b, p) in bag.iter().zip(&pcd) {
        assert_same_points(b, p);
        assert!(matches!(&b.point_times, PointTimes::Field(f) if f.name == "offset_time"));
        let worst = b
            .points
            .iter()
            .zip(&p.points)
            .map(|(q, r)| (q.t - r.t).abs())
            .fold(0.0, f64::max);
        assert!(worst <= 2e-9, "frame {}: {worst} s off", p.index);
    }
}

#[test]
fn without_a_time_field_times_are_derived_over_the_scan_and_flagged() {
    let truth = TruthTimes::read(&frames_dir().join("truth.csv")).unwrap();
    let first = truth.times[&0];
    let period_s = first.scan_end_s - first.scan_start_s;
    let options = InputOptions {
        scan_period_s: Some(period_s),
        ..InputOptions::default()
    };
    let (bag, pcd) = (bag_frames("none", &options), pcd_frames());
    assert_eq!(bag.len(), pcd.len());
    for (b, p) in bag.iter().zip(&pcd) {
        assert_same_points(b, p);
        assert!(b.times_derived());
        assert_eq!(b.scan_time_source, ScanTimeSource::ScanPeriod);
        let scan = truth.times[&p.index];
        assert!((b.scan_start_s - scan.scan_start_s).abs() <= 1e-9);
        let t: Vec<f64> = b.points.iter().map(|q| q.t).collect();
        assert_eq!(t[0], b.scan_start_s);
        assert!((t[t.len() - 1] - (b.scan_start_s + period_s)).abs() <= 1e-9);
        assert!(t.windows(2).all(|w| w[0] <= w[1]), "linear in point order");
        assert!(t.iter().all(|&x| x > 0.0), "never t = 0");
    }
}
