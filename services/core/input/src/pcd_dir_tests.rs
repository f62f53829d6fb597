//! A temporary directory of frames, read in order.

use super::*;
use crate::{InputError, ScanTimeSource};
use spacepose_geometry::{CloudFormat, Point, write_cloud};
use std::fs;

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
    let dir = PcdDir::open(tmp.path(), &InputOptions::default()).unwrap();
    assert_eq!(dir.len(), 4);
    assert!(!dir.has_truth() && dir.recorded_period_s().is_none());
    let frames: Vec<_> = dir.iter().map(Result::unwrap).collect();
    let idx: Vec<u64> = frames.iter().map(|f| f.index).collect();
    assert_eq!(idx, [1, 2, 3, 10]);
    for f in &frames {
        assert_eq!(f.scan_time_source, ScanTimeSource::PointTimes);
        assert_eq!(f.points, frame(f.index, 100 + f.index as usize));
        assert_eq!(f.scan_start_s, f.points[0].t);
        assert_eq!(f.scan_end_s, f.points.last().unwrap().t);
    }
    let rec = crate::Recording::PcdDir(dir);
    let mut cursor = rec.cursor();
    let by_cursor: Vec<u64> = std::iter::from_fn(|| rec.next_frame(&mut cursor))
        .map(|f| f.unwrap().index)
        .collect();
    assert_eq!(by_cursor, idx);
}

#[test]
fn truth_csv_gives_the_scan_times_and_the_period() {
    let tmp = tempfile::tempdir().unwrap();
    write_frames(tmp.path(), &[0, 1, 2], CloudFormat::PcdAscii);
    let truth = "frame,scan_start_s,scan_end_s,points\n0,0.5,2.0,100\n1,2.5,4.0,101\nbroken row\n";
    fs::write(tmp.path().join("truth.csv"), truth).unwrap();
    let dir = PcdDir::open(tmp.path(), &InputOptions::default()).unwrap();
    assert!(dir.has_truth());
    assert_eq!(dir.recorded_period_s(), Some(2.0));
    assert_eq!(dir.warnings().len(), 1);
    let frames: Vec<_> = dir.iter().map(Result::unwrap).collect();
    assert_eq!(
        (
            frames[1].scan_start_s,
            frames[1].scan_end_s,
            frames[1].scan_time_source
        ),
        (2.5, 4.0, ScanTimeSource::TruthCsv)
    );
    // Frame 2 has no row: falls back to its points.
    assert_eq!(frames[2].scan_time_source, ScanTimeSource::PointTimes);
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
    let dir = PcdDir::open(tmp.path(), &InputOptions::default()).unwrap();
    assert!(matches!(dir.warnings(), [InputError::Truth { .. }]));
    let results: Vec<_> = dir.iter().collect();
    assert_eq!(results.len(), 5);
    assert!(results[0].is_ok() && results[2].is_ok());
    assert!(matches!(results[1], Err(InputError::Frame { .. })));
    assert!(matches!(results[3], Err(InputError::Frame { .. })));
    assert!(matches!(results[4], Err(InputError::NoTimestamps(_))));
    let ok: Vec<u64> = dir.iter().filter_map(Result::ok).map(|f| f.index).collect();
    assert_eq!(ok, [0, 2]);
}

#[test]
fn missing_or_empty_directories_are_errors() {
    let tmp = tempfile::tempdir().unwrap();
    assert!(matches!(
        PcdDir::open(tmp.path(), &InputOptions::default()),
        Err(InputError::NoFrames(_))
    ));
    assert!(matches!(
        PcdDir::open(tmp.path().join("absent"), &InputOptions::default()),
        Err(InputError::Io { .. })
    ));
}

#[test]
fn shifting_time_moves_the_scan_and_the_points() {
    let tmp = tempfile::tempdir().unwrap();
    write_frames(tmp.path(), &[0], CloudFormat::PcdBinary);
    let dir = PcdDir::open(tmp.path(), &InputOptions::default()).unwrap();
    let mut f = dir.read(0).unwrap().unwrap();
    let before = f.clone();
    f.shift_time(5.0);
    assert_eq!(f.scan_end_s, before.scan_end_s + 5.0);
    assert_eq!(f.points[3].t, before.points[3].t + 5.0);
    assert!(dir.read(1).is_none());
}

#[test]
fn frame_names_are_recognised() {
    assert_eq!(frame_index(Path::new("a/frame_000042.pcd")), Some(42));
    assert_eq!(frame_index(Path::new("frame_7.PLY")), Some(7));
    assert_eq!(frame_index(Path::new("frame_.pcd")), None);
    assert_eq!(frame_index(Path::new("frame_12a.pcd")), None);
    assert_eq!(frame_index(Path::new("frame_000001.txt")), None);
    assert_eq!(frame_index(Path::new("truth.csv")), None);
}

/// A PCD of another tool, without a time field.
fn write_bare_pcd(path: &Path, n: usize) {
    let mut text = format!(
        "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {n}\nHEIGHT 1\n\
         VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA ascii\n"
    );
    for i in 0..n {
        text.push_str(&format!("{i} 1 10\n"));
    }
    fs::write(path, text).unwrap();
}

#[test]
fn a_pcd_without_time_field_gets_derived_times_and_the_flag() {
    let tmp = tempfile::tempdir().unwrap();
    write_bare_pcd(&tmp.path().join("frame_000000.pcd"), 5);
    write_bare_pcd(&tmp.path().join("frame_000001.pcd"), 5);
    fs::write(
        tmp.path().join("truth.csv"),
        "frame,scan_start_s,scan_end_s\n0,1.0,1.4\n",
    )
    .unwrap();
    let options = InputOptions {
        scan_period_s: Some(0.25),
        ..InputOptions::default()
    };
    let dir = PcdDir::open(tmp.path(), &options).unwrap();
    let frames: Vec<_> = dir.iter().map(Result::unwrap).collect();
    // With a truth row: linear over its interval.
    assert!(frames[0].times_derived());
    assert_eq!(frames[0].scan_time_source, ScanTimeSource::TruthCsv);
    let t: Vec<f64> = frames[0].points.iter().map(|p| p.t).collect();
    assert_eq!((t[0], t[4]), (1.0, 1.4));
    assert!((t[1] - 1.1).abs() < 1e-12);
    // Without: index times the configured period.
    assert!(frames[1].times_derived());
    assert_eq!(frames[1].scan_time_source, ScanTimeSource::ScanPeriod);
    assert_eq!((frames[1].scan_start_s, frames[1].scan_end_s), (0.25, 0.5));
    assert!(
        frames.iter().all(|f| f.points.iter().all(|p| p.t > 0.0)),
        "never t = 0"
    );
}
