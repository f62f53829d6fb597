//! Seeded fuzzing of the frame validation: 10^4 fuzzed frames (empty, above
//! capacity, every point with a NaN or infinite field, a non-finite or
//! reversed scan interval), interleaved with good frames. Never a panic.
//! An empty frame with a valid header is the observation "target not seen"
//! (crate docs): forwarded empty and counted in `empty_frames` and
//! `frames_without_target`, never rejected. Every other bad frame (an empty
//! one with a bad scan interval included) is rejected and counted under its
//! own reason; every good frame still passes.

use crate::{IngestConfig, IngestError, IngestStage, IngestStats};
use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spacepose_geometry::Point;

const BAD_FRAMES: u64 = 10_000;
const MAX_POINTS: usize = 256;

fn finite_point(rng: &mut impl Rng, i: usize) -> Point {
    Point::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(9.0..11.0),
        rng.random_range(0.0..1.0),
        i as f64 * 1e-3,
    )
}

/// A point with at least one NaN or infinite field.
fn non_finite_point(rng: &mut impl Rng, i: usize) -> Point {
    let mut p = finite_point(rng, i);
    let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY][rng.random_range(0..3)];
    match rng.random_range(0..5) {
        0 => p.x = bad,
        1 => p.y = bad,
        2 => p.z = bad,
        3 => p.intensity = bad,
        _ => p.t = f64::from(bad),
    }
    p
}

/// Which counter a fuzzed frame must land in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Reason {
    /// Valid header, no point: forwarded as "target not seen".
    Empty,
    Oversized,
    NonFinite,
    Other,
}

fn bad_frame(rng: &mut impl Rng) -> (Vec<Point>, f64, f64, Reason) {
    let n = rng.random_range(1..MAX_POINTS);
    match rng.random_range(0..4) {
        0 => (Vec::new(), 0.0, 0.1, Reason::Empty),
        1 => {
            let n = MAX_POINTS + rng.random_range(1..64);
            let pts = (0..n).map(|i| finite_point(rng, i)).collect();
            (pts, 0.0, 0.1, Reason::Oversized)
        }
        2 => {
            let pts = (0..n).map(|i| non_finite_point(rng, i)).collect();
            (pts, 0.0, 0.1, Reason::NonFinite)
        }
        _ => {
            // Some of them empty: a bad header is bad input, points or not.
            let n = if rng.random_range(0..4) == 0 { 0 } else { n };
            let pts = (0..n).map(|i| finite_point(rng, i)).collect();
            let (a, b) = match rng.random_range(0..4) {
                0 => (f64::NAN, 0.1),
                1 => (0.0, f64::INFINITY),
                2 => (f64::NEG_INFINITY, f64::NAN),
                _ => (0.2, 0.1), // ends before it starts
            };
            (pts, a, b, Reason::Other)
        }
    }
}

#[test]
fn ten_thousand_fuzzed_frames_are_rejected_or_forwarded_and_counted_by_reason() {
    let mut stage = IngestStage::new(IngestConfig {
        max_points: MAX_POINTS,
        ..IngestConfig::default()
    })
    .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(0xf022_1e57);
    let mut expected = IngestStats::default();
    let mut out = Vec::new();
    let mut good_frames = 0;
    for i in 0..BAD_FRAMES {
        let (points, start, end, reason) = bad_frame(&mut rng);
        let r = stage.process_into(&points, start, end, None, &mut out);
        match r {
            Ok(report) if reason == Reason::Empty => {
                assert_eq!((report.input_points, report.output_points), (0, 0));
                assert!(!report.target_seen, "frame {i}: {report:?}");
            }
            Ok(report) => panic!("bad frame {i} ({reason:?}) accepted: {report:?}"),
            Err(e) => {
                let got = match e {
                    IngestError::Oversized { .. } => Reason::Oversized,
                    IngestError::AllNonFinite { .. } => Reason::NonFinite,
                    IngestError::BadScanInterval { .. } => Reason::Other,
                    IngestError::InvalidConfig { .. } => panic!("config error on a frame: {e}"),
                };
                assert_eq!(got, reason, "frame {i}: {e}");
            }
        }
        assert!(out.is_empty());
        expected.frames_in += 1;
        match reason {
            Reason::Empty => {
                expected.frames_out += 1;
                expected.empty_frames += 1;
                expected.frames_without_target += 1;
                expected.frames_empty_after_crop += 1;
                expected.frames_without_prediction += 1;
            }
            Reason::Oversized => expected.rejected_oversized += 1,
            Reason::NonFinite => {
                expected.rejected_all_non_finite += 1;
                expected.frames_with_non_finite += 1;
            }
            Reason::Other => expected.rejected_other += 1,
        }
        // Every 100th bad frame, a good one still passes.
        if i % 100 == 99 {
            let good: Vec<Point> = (0..100).map(|k| finite_point(&mut rng, k)).collect();
            let report = stage.process_into(&good, 0.0, 0.1, None, &mut out).unwrap();
            assert_eq!(report.input_points, 100);
            assert!(!out.is_empty());
            good_frames += 1;
        }
    }
    let s = *stage.stats();
    assert_eq!(s.frames_in, expected.frames_in + good_frames);
    assert_eq!(s.frames_out, expected.frames_out + good_frames);
    assert_eq!(s.empty_frames, expected.empty_frames);
    assert_eq!(s.frames_without_target, expected.frames_without_target);
    assert_eq!(s.frames_empty_after_crop, expected.frames_empty_after_crop);
    assert_eq!(
        s.frames_without_prediction,
        expected.frames_without_prediction + good_frames
    );
    assert_eq!(s.rejected_oversized, expected.rejected_oversized);
    assert_eq!(s.rejected_all_non_finite, expected.rejected_all_non_finite);
    assert_eq!(s.frames_with_non_finite, expected.frames_with_non_finite);
    assert_eq!(s.rejected_other, expected.rejected_other);
    let rejected = s.rejected_oversized + s.rejected_all_non_finite + s.rejected_other;
    assert_eq!(rejected + s.empty_frames, BAD_FRAMES);
    assert!(s.empty_frames > 0 && s.rejected_oversized > 0);
    assert!(s.rejected_all_non_finite > 0 && s.rejected_other > 0);
    println!(
        "ingest fuzz: {BAD_FRAMES} fuzzed frames: {rejected} rejected (oversized {}, all non-finite \
         {}, bad interval {}), {} empty ones with a valid header forwarded as \
         \"target not seen\"; {good_frames} good frames between them passed",
        s.rejected_oversized, s.rejected_all_non_finite, s.rejected_other, s.empty_frames
    );
}
