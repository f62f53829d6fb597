use super::*;
use nalgebra::{Matrix6, Rotation3};
use spacepose_geometry::Pose;

/// A closed box 2 × 2 × 1 m (faces sampled every 2 cm), body frame.
fn slab() -> Vec<Vector3<f64>> {
    let mut pts = Vec::new();
    let n = 100;
    for i in 0..=n {
        for j in 0..=n {
            let (a, b) = (
                i as f64 / n as f64 * 2.0 - 1.0,
                j as f64 / n as f64 * 2.0 - 1.0,
            );
            pts.push(Vector3::new(a, b, -0.5));
            pts.push(Vector3::new(a, b, 0.5));
            pts.push(Vector3::new(a, 1.0, b * 0.5));
            pts.push(Vector3::new(a, -1.0, b * 0.5));
            pts.push(Vector3::new(1.0, a, b * 0.5));
            pts.push(Vector3::new(-1.0, a, b * 0.5));
        }
    }
    pts
}

fn prediction(w_target: Vector3<f64>) -> Prediction {
    Prediction {
        t: 1.0,
        pose: Pose::new(Rotation3::identity(), Vector3::new(0.0, 0.0, 15.0)),
        v_sensor: Vector3::zeros(),
        w_target,
        w_inertial_sensor: nalgebra::Vector3::zeros(),
        covariance: Matrix6::identity() * 1e-6,
        attitude_covariance: spacepose_filter::Matrix9::identity() * 1e-6,
        position_covariance: Matrix6::identity() * 1e-6,
    }
}

fn point(x: f64, y: f64, z: f64, t: f64) -> Point {
    Point::new(x as f32, y as f32, z as f32, 1.0, t)
}

/// The depth test alone (no bounding box).
fn depth_only() -> VisibilityConfig {
    VisibilityConfig {
        outside_box: false,
        ..VisibilityConfig::default()
    }
}

/// The near face is at 14.5 m: points on it stay, a mirror ghost 2 m
/// behind it goes, and points beside the target stay whatever their range.
#[test]
fn ghosts_behind_the_near_face_are_dropped_and_surface_points_kept() {
    let model = VisibilityModel::new(&slab(), 0.075);
    let mut points: Vec<Point> = (0..40)
        .map(|i| point(-0.8 + i as f64 * 0.04, 0.1, 14.51, 1.0))
        .collect();
    points.push(point(0.2, 0.2, 16.5, 1.0));
    points.push(point(0.0, -0.3, 17.0, 1.0));
    points.push(point(3.0, 0.0, 20.0, 1.0));
    let gated = model
        .gate(
            points.clone(),
            false,
            &prediction(Vector3::zeros()),
            &depth_only(),
        )
        .unwrap();
    assert_eq!(gated.behind, 2);
    assert!(!gated.overruled);
    assert_eq!(gated.points.len(), points.len() - 2);
    assert!(gated.points.iter().all(|p| p.z < 16.0 || p.x > 2.0));
}

/// Where the neighbourhood holds no surface (beside the target) every point
/// stays; near the silhouette a point stays within the tolerance of the
/// farthest surface nearby (the rim), and a ghost beyond it goes.
#[test]
fn beside_the_target_points_stay_and_near_the_rim_the_rim_bounds_them() {
    let model = VisibilityModel::new(&slab(), 0.075);
    let points = vec![
        point(3.0, 0.0, 18.0, 1.0),
        point(0.99, 0.0, 14.6, 1.0),
        point(0.98, 0.0, 16.5, 1.0),
    ];
    let gated = model
        .gate(points, false, &prediction(Vector3::zeros()), &depth_only())
        .unwrap();
    assert_eq!(gated.behind, 1);
    assert!(gated.points.iter().all(|p| p.z < 16.0 || p.x > 2.0));
}

/// A point measured at the scan start is tested where the predicted motion
/// puts it at the scan end: a return from the near face, 0.5 s before the
/// end of a 1 rad/s turn about the line of sight, is not a ghost.
#[test]
fn points_are_tested_at_the_scan_end() {
    let model = VisibilityModel::new(&slab(), 0.075);
    let r = Rotation3::from_axis_angle(&Vector3::z_axis(), -0.5);
    let p = r * Vector3::new(0.6, 0.3, -0.49) + Vector3::new(0.0, 0.0, 15.0);
    let points = vec![point(p.x, p.y, p.z, 0.5)];
    let gated = model
        .gate(
            points.clone(),
            false,
            &prediction(Vector3::new(0.0, 0.0, 1.0)),
            &VisibilityConfig::default(),
        )
        .unwrap();
    assert_eq!(gated.behind, 0);
    assert_eq!(gated.points.len(), 1);
}

/// When most points would go, the prediction is doubted and none goes;
/// disabled, the gate keeps everything.
#[test]
fn a_frame_mostly_behind_is_overruled_and_the_gate_can_be_switched_off() {
    let model = VisibilityModel::new(&slab(), 0.075);
    let mut points: Vec<Point> = (0..10)
        .map(|i| point(0.05 * i as f64, 0.0, 17.0, 1.0))
        .collect();
    points.push(point(0.0, 0.0, 14.5, 1.0));
    let gated = model
        .gate(
            points.clone(),
            false,
            &prediction(Vector3::zeros()),
            &VisibilityConfig::default(),
        )
        .unwrap();
    assert!(gated.overruled);
    assert_eq!(gated.behind, 10);
    assert_eq!(gated.points.len(), 11, "none dropped");
    let off = VisibilityConfig {
        enabled: false,
        ..VisibilityConfig::default()
    };
    let gated = model
        .gate(points.clone(), false, &prediction(Vector3::zeros()), &off)
        .unwrap();
    assert_eq!((gated.behind, gated.points.len()), (0, 11));
}

/// With `outside_box`, a point beside the target beyond the grown box goes
/// too (what holds the target: a facility's arm), one just outside the box
/// within the tolerance stays; the box grows with the prediction's
/// uncertainty, so a start-up's wide prediction keeps the arm.
#[test]
fn points_outside_the_grown_box_go() {
    let model = VisibilityModel::new(&slab(), 0.075);
    // Near face at z = 14.5; an arm below the slab (body y > 1), a return
    // 10 cm past the edge, a surface return.
    let points = vec![
        point(0.0, 2.5, 14.8, 1.0),
        point(0.0, 1.1, 14.6, 1.0),
        point(0.0, 0.2, 14.51, 1.0),
    ];
    let sure = prediction(Vector3::zeros());
    let gated = model
        .gate(points.clone(), false, &sure, &VisibilityConfig::default())
        .unwrap();
    assert_eq!(gated.behind, 1);
    assert!(gated.points.iter().all(|p| p.y < 2.0));
    let kept = model
        .gate(points.clone(), false, &sure, &depth_only())
        .unwrap();
    assert_eq!(kept.behind, 0);
    // 60° (3σ) of attitude doubt, a start-up's, grows the box by
    // 1.5 m tan 60° = 2.6 m: the arm stays.
    let mut unsure = sure;
    for i in 0..3 {
        unsure.covariance[(i, i)] = (60f64 / 3.0).to_radians().powi(2);
    }
    let gated = model
        .gate(points, false, &unsure, &VisibilityConfig::default())
        .unwrap();
    assert_eq!(gated.behind, 0);
}

#[test]
fn the_config_fails_on_nan_and_out_of_range() {
    assert!(VisibilityConfig::default().validate().is_ok());
    for c in [
        VisibilityConfig {
            tolerance_m: f64::NAN,
            ..VisibilityConfig::default()
        },
        VisibilityConfig {
            pose_allowance_deg: 95.0,
            ..VisibilityConfig::default()
        },
        VisibilityConfig {
            max_dropped_fraction: 1.5,
            ..VisibilityConfig::default()
        },
        VisibilityConfig {
            refit_min_fraction: f64::NAN,
            ..VisibilityConfig::default()
        },
    ] {
        assert!(c.validate().is_err());
    }
}

/// One point per cell: the thinned model's size follows the area over the
/// cell, and the radius is the farthest point's.
#[test]
fn the_model_is_thinned_to_one_point_per_cell() {
    let model = VisibilityModel::new(&slab(), 0.1);
    let area = 2.0 * 4.0 + 4.0 * 2.0; // m²
    let n = model.len() as f64;
    assert!(n > 0.5 * area / 0.01 && n < 3.0 * area / 0.01, "{n}");
    assert!((model.radius_m - 1.5).abs() < 1e-9, "corner (1, 1, 0.5)");
}
