//! Bad input and the crop of [`IngestStage`].

use crate::{IngestConfig, IngestError, IngestStage, RoiKind, TargetPrediction};
use nalgebra::Vector3;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spacepose_geometry::Point;

/// Points uniformly in a 1 m cube about (0, 0, 10), timestamps over [0, 1].
fn cube(n: usize, seed: u64) -> Vec<Point> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|i| {
            Point::new(
                rng.random_range(-0.5..0.5),
                rng.random_range(-0.5..0.5),
                rng.random_range(9.5..10.5),
                1.0,
                i as f64 / n as f64,
            )
        })
        .collect()
}

fn stage() -> IngestStage {
    IngestStage::new(IngestConfig {
        max_points: 10_000,
        ..IngestConfig::default()
    })
    .unwrap()
}

#[test]
fn bad_frames_are_rejected_counted_and_the_next_frame_still_passes() {
    let mut s = stage();
    let good = cube(2000, 1);
    // An empty frame with a bad header is bad input (below: with a valid
    // header it is an observation).
    assert!(matches!(
        s.process(&[], 1.0, 0.5, None),
        Err(IngestError::BadScanInterval { .. })
    ));
    assert!(matches!(
        s.process(&cube(10_001, 2), 0.0, 1.0, None),
        Err(IngestError::Oversized {
            points: 10_001,
            capacity: 10_000
        })
    ));
    let nan = vec![Point::new(f32::NAN, 0.0, 1.0, 1.0, 0.0); 50];
    assert!(matches!(
        s.process(&nan, 0.0, 1.0, None),
        Err(IngestError::AllNonFinite { points: 50 })
    ));
    assert!(matches!(
        s.process(&good, f64::NAN, 1.0, None),
        Err(IngestError::BadScanInterval { .. })
    ));
    assert!(matches!(
        s.process(&good, 2.0, 1.0, None),
        Err(IngestError::BadScanInterval { .. })
    ));
    // Some NaN / infinite points: dropped and counted, the rest goes through.
    let mut mixed = good.clone();
    mixed[3].y = f32::NAN;
    mixed[7].t = f64::INFINITY;
    mixed[9].intensity = f32::NEG_INFINITY;
    let (out, report) = s.process(&mixed, 0.0, 1.0, None).unwrap();
    assert_eq!(report.non_finite_points, 3);
    assert_eq!(report.output_points, 1997);
    assert!(!out.is_empty() && out.iter().all(Point::is_finite));
    let (_, report) = s.process(&good, 0.0, 1.0, None).unwrap();
    assert_eq!(report.non_finite_points, 0);
    let st = *s.stats();
    assert_eq!(st.frames_in, 7);
    assert_eq!(st.frames_out, 2);
    assert_eq!(st.rejected_oversized, 1);
    assert_eq!(st.rejected_all_non_finite, 1);
    assert_eq!(st.rejected_other, 3);
    assert_eq!(st.frames_with_non_finite, 2);
    assert_eq!(st.non_finite_points, 3);
    assert_eq!((st.empty_frames, st.frames_without_target), (0, 0));
}

#[test]
fn frames_without_the_target_are_forwarded_as_observations() {
    let mut s = stage();
    // The sensor looked away: a well-formed frame with no point.
    let (out, r) = s.process(&[], 3.0, 4.0, None).unwrap();
    assert!(out.is_empty());
    assert_eq!(
        (r.input_points, r.output_points, r.target_seen),
        (0, 0, false)
    );
    // A few points of the target (fewer than min_target_points = 20).
    let (out, r) = s.process(&cube(5, 4)[..], 4.0, 5.0, None).unwrap();
    assert_eq!((out.len(), r.target_seen), (5, false));
    // Points, but none in the region of interest (a far wall).
    let wall = vec![Point::new(0.0, 0.0, 80.0, 1.0, 5.5); 300];
    let (out, r) = s.process(&wall, 5.0, 6.0, None).unwrap();
    assert!(out.is_empty() && !r.target_seen && r.cropped_points == 300);
    // The target is back.
    let (out, r) = s.process(&cube(2000, 5), 6.0, 7.0, None).unwrap();
    assert!(out.len() >= 20 && r.target_seen);
    let st = *s.stats();
    assert_eq!((st.frames_in, st.frames_out), (4, 4));
    assert_eq!((st.empty_frames, st.frames_without_target), (1, 3));
    assert_eq!(st.frames_empty_after_crop, 2);
    let rejected = st.rejected_oversized + st.rejected_all_non_finite + st.rejected_other;
    assert_eq!(rejected, 0);
}

#[test]
fn the_crop_keeps_every_point_inside_in_time_order() {
    // Two points per 2 cm cell, 1 mm apart: nothing is merged (the tracker
    // voxel-filters after its motion compensation).
    let mut pts = Vec::new();
    for k in 0..500 {
        let x = 0.02 * k as f32 + 0.005;
        pts.push(Point::new(x, 0.005, 10.005, 1.0, 0.002 * k as f64));
        pts.push(Point::new(
            x + 0.001,
            0.005,
            10.005,
            3.0,
            0.002 * k as f64 + 0.001,
        ));
    }
    // A 10 m line: without a prediction the detection would keep the part
    // of it a target could fill; the range gate alone keeps it all.
    let mut s = IngestStage::new(IngestConfig {
        detect: crate::DetectConfig {
            enabled: false,
            ..Default::default()
        },
        ..IngestConfig::default()
    })
    .unwrap();
    let (out, report) = s.process(&pts, 0.0, 1.0, None).unwrap();
    assert_eq!(report.roi, RoiKind::RangeOnly);
    assert_eq!(report.output_points, 1000);
    assert_eq!(out, pts);
}

#[test]
fn a_prediction_crops_to_the_sphere_and_a_wrong_one_empties_the_frame() {
    let mut s = stage();
    let mut pts = cube(1000, 3);
    // A far point (wall) and a near one (window).
    pts.push(Point::new(0.0, 0.0, 16.0, 1.0, 0.5));
    pts.push(Point::new(0.0, 0.0, 0.3, 1.0, 0.5));
    let pred = TargetPrediction {
        t_s: 0.0,
        p_sensor_target: Vector3::new(0.0, 0.0, 10.0),
        v_sensor: Vector3::zeros(),
        attitude: None,
    };
    let (_, r) = s.process(&pts, 0.0, 1.0, Some(&pred)).unwrap();
    assert_eq!(r.roi, RoiKind::Predicted);
    assert_eq!((r.output_points, r.cropped_points), (1000, 2));
    // Without a prediction, the target found in the frame: the far point
    // is out of its sphere too.
    let (_, r) = s.process(&pts, 0.0, 1.0, None).unwrap();
    assert_eq!(r.roi, RoiKind::Detected);
    assert_eq!((r.output_points, r.cropped_points), (1000, 2));
    let far = TargetPrediction {
        p_sensor_target: Vector3::new(0.0, 0.0, 30.0),
        ..pred
    };
    let (out, r) = s.process(&pts, 0.0, 1.0, Some(&far)).unwrap();
    assert!(out.is_empty() && r.output_points == 0);
    assert_eq!(s.stats().frames_empty_after_crop, 1);
    assert_eq!(s.stats().frames_without_prediction, 1);
    assert_eq!(s.stats().frames_detected, 1);
}

#[test]
fn an_invalid_config_is_refused() {
    assert!(
        IngestStage::new(IngestConfig {
            max_range_m: f64::NAN,
            ..IngestConfig::default()
        })
        .is_err()
    );
}
