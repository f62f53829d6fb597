//! Replay of a temporary directory of frames.

use crate::{ReplayDir, ReplayError, TimeSource};
use spacepose_geometry::{CloudFormat, Point, write_cloud};
use std::fs;
use std::path::Path;

fn frame(k: u64, n: usize) -> Vec<Point> {
    (0..n)
        .map(|i| {
            let t = k as f64 + 0.28 + 0.72 * i as f64 / n as f64;
            Point::new(i as f32 * 0.01, 0.0, 10.0, 1.0, t)
        })
        .collect()
}

fn write_frames(dir: &Path, ks: &[u64], format: CloudFormat) {
    for &k in ks {
        let path = dir.join(format!("frame_{k:06}.{}", format.extension()));
        write_cloud(&path, &frame(k, 100 + k as usize), format).unwrap();
    }
}

#[test]
fn frames_come_in_index_order_with_point_times_without_truth() {
    let tmp = tempfile::tempdir().unwrap();
    write_frames(tmp.path(), &[3, 1, 10], CloudFormat::PcdBinary);
    write_frames(tmp.path(), &[2], CloudFormat::PlyBinary);
    fs::write(tmp.path().join("notes.txt"), "not a frame").unwrap();
    let dir = ReplayDir::open(tmp.path()).unwrap();
    assert_eq!(dir.len(), 4);
    assert!(!dir.has_truth() && dir.recorded_period_s().is_none());
    let frames: Vec<_> = dir.iter().map(Result::unwrap).collect();
    let idx: Vec<u64> = frames.iter().map(|f| f.index).collect();
    assert_eq!(idx, [1, 2, 3, 10]);
    for f in &frames {
        assert_eq!(f.time_source, TimeSource::PointTimestamps);
        assert_eq!(f.points, frame(f.index, 100 + f.index as usize));
        assert_eq!(f.scan_start_s, f.points[0].t);
        assert_eq!(f.scan_end_s, f.points.last().unwrap().t);
    }
}

#[test]
fn truth_csv_gives_the_scan_times_and_the_period() {
    let tmp = tempfile::tempdir().unwrap();
    write_frames(tmp.path(), &[0, 1, 2], CloudFormat::PcdAscii);
    let truth = "frame,scan_start_s,scan_end_s,points\n0,0.5,2.0,100\n1,2.5,4.0,101\nbroken row\n";
    fs::write(tmp.path().join("truth.csv"), truth).unwrap();
    let dir = ReplayDir::open(tmp.path()).unwrap();
    assert!(dir.has_truth());
    assert_eq!(dir.recorded_period_s(), Some(2.0));
    assert_eq!(dir.warnings().len(), 1);
    let frames: Vec<_> = dir.iter().map(Result::unwrap).collect();
    assert_eq!(
        (
            frames[1].scan_start_s,
            frames[1].scan_end_s,
            frames[1].time_source
        ),
        (2.5, 4.0, TimeSource::TruthCsv)
    );
    // Frame 2 has no row: falls back to its points.
    assert_eq!(frames[2].time_source, TimeSource::PointTimestamps);
}

#[test]
fn corrupt_files_are_reported_and_skipped() {
    let tmp = tempfile::tempdir().unwrap();
    write_frames(tmp.path(), &[0, 2], CloudFormat::PcdBinary);
    fs::write(tmp.path().join("frame_000001.pcd"), "garbage\x00\x01").unwrap();
    // A PCD cut in the middle of its data.
    let good = fs::read(tmp.path().join("frame_000002.pcd")).unwrap();
    fs::write(tmp.path().join("frame_000003.pcd"), &good[..good.len() - 7]).unwrap();
    // A valid file whose points have no finite timestamp.
    let nan = vec![Point::new(1.0, 2.0, 3.0, 1.0, f64::NAN); 5];
    write_cloud(
        tmp.path().join("frame_000004.ply"),
        &nan,
        CloudFormat::PlyBinary,
    )
    .unwrap();
    // An unparsable truth header is a warning, not fatal.
    fs::write(tmp.path().join("truth.csv"), "a,b\n1,2\n").unwrap();
    let dir = ReplayDir::open(tmp.path()).unwrap();
    assert!(matches!(dir.warnings(), [ReplayError::Truth { .. }]));
    let results: Vec<_> = dir.iter().collect();
    assert_eq!(results.len(), 5);
    assert!(results[0].is_ok() && results[2].is_ok());
    assert!(matches!(results[1], Err(ReplayError::Frame { .. })));
    assert!(matches!(results[3], Err(ReplayError::Frame { .. })));
    assert!(matches!(results[4], Err(ReplayError::NoTimestamps(_))));
    let ok: Vec<u64> = dir.iter().filter_map(Result::ok).map(|f| f.index).collect();
    assert_eq!(ok, [0, 2]);
}

#[test]
fn missing_or_empty_directories_are_errors() {
    let tmp = tempfile::tempdir().unwrap();
    assert!(matches!(
        ReplayDir::open(tmp.path()),
        Err(ReplayError::NoFrames(_))
    ));
    assert!(matches!(
        ReplayDir::open(tmp.path().join("absent")),
        Err(ReplayError::Dir { .. })
    ));
}

#[test]
fn shifting_time_moves_the_scan_and_the_points() {
    let tmp = tempfile::tempdir().unwrap();
    write_frames(tmp.path(), &[0], CloudFormat::PcdBinary);
    let dir = ReplayDir::open(tmp.path()).unwrap();
    let mut f = dir.read(0).unwrap().unwrap();
    let before = f.clone();
    f.shift_time(5.0);
    assert_eq!(f.scan_end_s, before.scan_end_s + 5.0);
    assert_eq!(f.points[3].t, before.points[3].t + 5.0);
    assert!(dir.read(1).is_none());
}
