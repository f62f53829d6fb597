use super::*;
use nalgebra::{Rotation3, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spacepose_model::Target;

fn config() -> PreprocessConfig {
    PreprocessConfig {
        image_size: 64,
        roi_side_m: 4.0,
        trim: DEFAULT_TRIM,
    }
}

/// The visible face of an axis-aligned cube of side 1 m centred at (0, 0, 10),
/// densely sampled: the face z = 9.5 seen from the sensor.
fn cube_front_face(step: f64) -> Vec<Point> {
    let mut pts = Vec::new();
    let n = (1.0 / step) as i32;
    for i in 0..n {
        for j in 0..n {
            let x = -0.5 + (i as f64 + 0.5) * step;
            let y = -0.5 + (j as f64 + 0.5) * step;
            pts.push(Point::from_vector(&Vector3::new(x, y, 9.5), 1.0, 0.0));
        }
    }
    pts
}

#[test]
fn cube_face_projects_to_the_expected_square() {
    let pts = cube_front_face(0.01);
    let img = preprocess(&pts, &config()).unwrap();
    assert_eq!(img.points_in_roi, pts.len());
    assert!((img.roi_centre - Vector3::new(0.0, 0.0, 9.5)).norm() < 1e-9);
    // A flat face at the centroid's depth reads 0.5 (Eq. 3), a 1 m square
    // is 16 pixels of 6.25 cm, centred: columns and rows 24..40.
    for row in 0..64 {
        for col in 0..64 {
            let v = img.pixels[row * 64 + col];
            let inside = (24..40).contains(&row) && (24..40).contains(&col);
            if inside {
                assert!((v - 0.5).abs() < 1e-6, "({row},{col}) = {v}");
            } else {
                assert_eq!(v, 0.0, "({row},{col})");
            }
        }
    }
}

#[test]
fn depth_values_follow_eq3_and_the_image_orientation() {
    // Three points: the centroid (trimmed mean) sits on the middle one.
    let mut pts = cube_front_face(0.05);
    // A nearer point at +x (right), and a farther one at +y (down).
    pts.push(Point::from_vector(&Vector3::new(1.5, 0.0, 8.5), 1.0, 0.0));
    pts.push(Point::from_vector(&Vector3::new(0.0, 1.5, 10.5), 1.0, 0.0));
    let img = preprocess(&pts, &config()).unwrap();
    let c = img.roi_centre;
    let pix = |x: f64, y: f64| {
        let col = ((x - c.x + 2.0) * 16.0) as usize;
        let row = ((y - c.y + 2.0) * 16.0) as usize;
        img.pixels[row * 64 + col]
    };
    let expect = |z: f64| ((z - c.z + 2.0) / 4.0) as f32;
    assert!((pix(1.5, 0.0) - expect(8.5)).abs() < 1e-6);
    assert!((pix(0.0, 1.5) - expect(10.5)).abs() < 1e-6);
    assert!(pix(1.5, 0.0) < 0.5 && pix(0.0, 1.5) > 0.5);
    assert!(img.pixels.iter().all(|v| (0.0..=1.0).contains(v)));
}

#[test]
fn pixel_is_the_mean_of_its_points() {
    let mut pts = cube_front_face(0.1);
    let target_col_x = 1.51; // well inside one pixel
    pts.push(Point::from_vector(
        &Vector3::new(target_col_x, 0.01, 9.0),
        1.0,
        0.0,
    ));
    pts.push(Point::from_vector(
        &Vector3::new(target_col_x, 0.01, 10.0),
        1.0,
        0.0,
    ));
    let img = preprocess(&pts, &config()).unwrap();
    let c = img.roi_centre;
    let col = ((target_col_x - c.x + 2.0) * 16.0) as usize;
    let row = ((0.01 - c.y + 2.0) * 16.0) as usize;
    let expected = (((9.0 - c.z + 2.0) / 4.0 + (10.0 - c.z + 2.0) / 4.0) / 2.0) as f32;
    assert!((img.pixels[row * 64 + col] - expected).abs() < 1e-6);
}

#[test]
fn roi_and_centroid_resist_outliers() {
    let mut pts = cube_front_face(0.02); // 2500 points
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    // 20 % gross outliers up to 50 m away, on one side.
    for _ in 0..500 {
        let p = Vector3::new(
            rng.random_range(5.0..50.0),
            rng.random_range(5.0..50.0),
            rng.random_range(20.0..60.0),
        );
        pts.push(Point::from_vector(&p, 1.0, 0.0));
    }
    let img = preprocess(&pts, &config()).unwrap();
    let plain = spacepose_geometry::centroid(&pts).unwrap();
    assert!((plain - Vector3::new(0.0, 0.0, 9.5)).norm() > 5.0);
    assert!(
        (img.roi_centre - Vector3::new(0.0, 0.0, 9.5)).norm() < 0.3,
        "trimmed centroid {:?}",
        img.roi_centre
    );
    assert_eq!(img.points_in_roi, 2500, "outliers are outside the ROI");
}

#[test]
fn bad_input_is_an_error() {
    assert!(matches!(
        preprocess(&[], &config()),
        Err(CnnError::EmptyCloud)
    ));
    let nan = vec![Point::new(f32::NAN, 0.0, 1.0, 1.0, 0.0); 4];
    assert!(matches!(
        preprocess(&nan, &config()),
        Err(CnnError::Centroid(_))
    ));
    let pts = cube_front_face(0.1);
    for size in [32, 300] {
        let c = PreprocessConfig {
            image_size: size,
            ..config()
        };
        assert!(matches!(
            preprocess(&pts, &c),
            Err(CnnError::ImageSize { .. })
        ));
    }
    let c = PreprocessConfig {
        roi_side_m: f64::NAN,
        ..config()
    };
    assert!(matches!(
        preprocess(&pts, &c),
        Err(CnnError::InvalidParameter { .. })
    ));
}

#[test]
fn roi_side_of_deos_is_4_m() {
    let deos = Target::builtin("deos").unwrap();
    assert_eq!(roi_side_for(&deos), 4.0);
}

#[test]
fn roi_keeps_the_whole_target() {
    // Ideal sensor, random attitudes at 8 m: every target point in the ROI,
    // and the centre-of-mass offset well inside l/2.
    use spacepose_lidar_sim::{Effects, LidarSimulator, SensorConfig};
    let deos = std::sync::Arc::new(Target::builtin("deos").unwrap());
    let mut sensor = SensorConfig::livox_mid40();
    sensor.effects = Effects::none();
    sensor.integration_time_s = 0.1;
    let sim = LidarSimulator::new(deos.clone(), sensor).unwrap();
    let config = PreprocessConfig::for_target(&deos, 64).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let mut max_offset = 0.0f64;
    for k in 0..40 {
        let truth = spacepose_scenario::TruthState {
            t: 1.0,
            t_sensor_target: spacepose_geometry::Pose::new(
                crate::domain::random_rotation(&mut rng),
                Vector3::new(0.0, 0.0, 8.0),
            ),
            v_sensor_target: Vector3::zeros(),
            w_target: Vector3::zeros(),
        };
        let frame = sim.simulate(&truth, &mut LidarSimulator::frame_rng(9, k));
        let img = preprocess(&frame.points, &config).unwrap();
        assert_eq!(img.points_in_roi, frame.points.len(), "frame {k}");
        let offset = truth.t_sensor_target.translation - img.roi_centre;
        max_offset = max_offset.max(offset.amax());
    }
    println!("largest |p - c| component over 40 attitudes: {max_offset:.2} m (l/2 = 2 m)");
    assert!(max_offset < 1.5);
    let _ = Rotation3::<f64>::identity();
}

#[test]
fn cube_seen_edge_on_gives_a_depth_ramp() {
    // A 1 m cube centred at (0, 0, 10), rotated 45° about y: the sensor sees
    // two faces meeting at the near vertical edge x = 0, z = 10 − √2/2, and
    // the depth grows as |x| (45° faces). Sample both faces densely.
    let r = Rotation3::from_axis_angle(&Vector3::y_axis(), std::f64::consts::FRAC_PI_4);
    let centre = Vector3::new(0.0, 0.0, 10.0);
    let mut pts = Vec::new();
    let n = 200;
    for i in 0..n {
        for j in 0..n {
            let a = -0.5 + (i as f64 + 0.5) / n as f64;
            let b = -0.5 + (j as f64 + 0.5) / n as f64;
            // Faces x = +0.5 and z = −0.5 of the body cube face the sensor after R.
            for body in [Vector3::new(0.5, b, a), Vector3::new(a, b, -0.5)] {
                pts.push(Point::from_vector(&(r * body + centre), 1.0, 0.0));
            }
        }
    }
    let img = preprocess(&pts, &config()).unwrap();
    let c = img.roi_centre;
    let z_edge = 10.0 - std::f64::consts::FRAC_1_SQRT_2;
    let mut checked = 0;
    for row in 0..64 {
        for col in 0..64 {
            let v = f64::from(img.pixels[row * 64 + col]);
            let x = c.x - 2.0 + (col as f64 + 0.5) / 16.0;
            let y = c.y - 2.0 + (row as f64 + 0.5) / 16.0;
            let on_cube = x.abs() < std::f64::consts::FRAC_1_SQRT_2 - 0.07 && y.abs() < 0.45;
            if on_cube {
                let expected = (z_edge + x.abs() - c.z + 2.0) / 4.0;
                // Half a pixel of ramp (3.1 cm / 4 m) plus the averaging at the edge.
                assert!(
                    (v - expected).abs() < 0.01,
                    "({row},{col}) {v} vs {expected}"
                );
                checked += 1;
            } else if x.abs() > 0.75 || y.abs() > 0.55 {
                assert_eq!(v, 0.0, "({row},{col}) must be empty");
            }
        }
    }
    assert!(checked > 250, "{checked} pixels checked");
}
