use super::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn random_cloud(n: usize, seed: u64) -> Vec<Point> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|i| {
            Point::new(
                rng.random_range(-1.5f32..1.5),
                rng.random_range(-1.5f32..1.5),
                rng.random_range(8.0f32..11.0),
                rng.random_range(0.0f32..1.0),
                1.7e9 + i as f64 * 1e-5,
            )
        })
        .collect()
}

#[test]
fn each_voxel_keeps_mean_position_timestamp_and_intensity() {
    // Two points in voxel [0, 0.1)^3, one in voxel [0.1, 0.2) x [0, 0.1)^2.
    let points = [
        Point::new(0.01, 0.02, 0.03, 1.0, 100.0),
        Point::new(0.05, 0.06, 0.07, 3.0, 100.5),
        Point::new(0.15, 0.05, 0.05, 2.0, 7.0),
    ];
    let out = voxel_filter(&points, 0.1).unwrap();
    assert_eq!(out.dropped_non_finite, 0);
    assert_eq!(out.points.len(), 2);
    let a = out.points[0];
    assert!((a.x - 0.03).abs() < 1e-7 && (a.y - 0.04).abs() < 1e-7);
    assert!((a.z - 0.05).abs() < 1e-7);
    assert_eq!(a.t, 100.25);
    assert_eq!(a.intensity, 2.0);
    assert_eq!(out.points[1], points[2]);
}

#[test]
fn mean_timestamp_is_precise_on_an_absolute_clock() {
    let t0 = 1.7e9;
    let points: Vec<Point> = (0..1000)
        .map(|i| Point::new(0.5, 0.5, 0.5, 0.0, t0 + i as f64 * 1e-6))
        .collect();
    let out = voxel_filter(&points, 1.0).unwrap();
    assert_eq!(out.points.len(), 1);
    let expected = t0 + 999.0 * 1e-6 / 2.0;
    assert!(
        (out.points[0].t - expected).abs() < 1e-9,
        "{}",
        out.points[0].t - expected
    );
}

#[test]
fn means_match_a_brute_force_grouping() {
    let points = random_cloud(2000, 7);
    let leaf = 0.3;
    let out = voxel_filter(&points, leaf).unwrap();
    let mut total = 0usize;
    for v in &out.points {
        let idx = |c: f32| (c as f64 / leaf).floor() as i64;
        let members: Vec<&Point> = points
            .iter()
            .filter(|p| idx(p.x) == idx(v.x) && idx(p.y) == idx(v.y) && idx(p.z) == idx(v.z))
            .collect();
        total += members.len();
        let n = members.len() as f64;
        let mean_t = members.iter().map(|p| p.t).sum::<f64>() / n;
        let mean_x = members.iter().map(|p| p.x as f64).sum::<f64>() / n;
        assert!((v.t - mean_t).abs() < 1e-6);
        assert!((v.x as f64 - mean_x).abs() < 1e-6);
    }
    assert_eq!(total, points.len());
}

#[test]
fn non_finite_points_are_skipped_and_counted() {
    let mut points = random_cloud(100, 1);
    points[3].x = f32::NAN;
    points[10].t = f64::NAN;
    points[50].intensity = f32::INFINITY;
    let out = voxel_filter(&points, 0.5).unwrap();
    assert_eq!(out.dropped_non_finite, 3);
    assert!(out.points.iter().all(Point::is_finite));
    let clean: Vec<Point> = points.iter().copied().filter(Point::is_finite).collect();
    assert_eq!(voxel_filter(&clean, 0.5).unwrap().points, out.points);
}

#[test]
fn bad_leaf_sizes_are_errors() {
    let points = random_cloud(10, 2);
    for leaf in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            voxel_filter(&points, leaf),
            Err(GeometryError::InvalidLeafSize(_))
        ));
    }
}

#[test]
fn far_points_are_an_error_not_a_collision() {
    let points = [Point::new(1.0e6, 0.0, 0.0, 0.0, 0.0)];
    assert!(matches!(
        voxel_filter(&points, 0.01),
        Err(GeometryError::VoxelIndexOutOfRange { .. })
    ));
    assert_eq!(voxel_filter(&points, 1.0).unwrap().points.len(), 1);
}

#[test]
fn negative_coordinates_use_floor_cells_and_order_is_deterministic() {
    let points = [
        Point::new(-0.05, 0.0, 0.0, 0.0, 0.0),
        Point::new(0.05, 0.0, 0.0, 0.0, 1.0),
        Point::new(-0.01, 0.0, 0.0, 0.0, 4.0),
    ];
    let out = voxel_filter(&points, 0.1).unwrap();
    assert_eq!(out.points.len(), 2);
    assert_eq!(out.points[0].t, 2.0);
    assert!((out.points[0].x + 0.03).abs() < 1e-7);
    assert_eq!(out.points[1].t, 1.0);
    let mut filter = VoxelFilter::new(0.1).unwrap();
    assert_eq!(filter.filter(&points).unwrap(), out);
    assert_eq!(filter.filter(&points).unwrap(), out);
    assert!(voxel_filter(&[], 0.1).unwrap().points.is_empty());
}

/// Points on three faces of a 2 m box, in raster (scan-line) order like a
/// lidar frame: about one point per 2 cm voxel.
fn scan_ordered_surface(n: usize, seed: u64) -> Vec<Point> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let per_face = n / 3;
    let side = (per_face as f64).sqrt() as usize;
    (0..n)
        .map(|i| {
            let j = i % per_face;
            let mut cell =
                |k: usize| k as f32 / side as f32 * 2.0 - 1.0 + rng.random_range(0.0f32..0.005);
            let (u, v) = (cell(j % side), cell(j / side));
            let (x, y, z) = match i / per_face {
                0 => (u, v, 9.0),
                1 => (-1.0, u, 10.0 + v),
                _ => (u, -1.0, 10.0 + v),
            };
            Point::new(x, y, z, 0.5, 1.7e9 + i as f64 * 1e-5)
        })
        .collect()
}

#[test]
fn timing_30k_points() {
    for (name, points) in [
        ("random-order volume", random_cloud(30_000, 3)),
        ("scan-order surface", scan_ordered_surface(30_000, 3)),
    ] {
        let mut filter = VoxelFilter::new(0.02).unwrap();
        let mut out = Vec::new();
        let mut best = std::time::Duration::MAX;
        for _ in 0..30 {
            let start = std::time::Instant::now();
            filter.filter_into(&points, &mut out).unwrap();
            best = best.min(start.elapsed());
        }
        let start = std::time::Instant::now();
        let one_shot = voxel_filter(&points, 0.02).unwrap().points;
        let one_shot_time = start.elapsed();
        println!(
            "voxel filter, 30k {name} points, leaf 2 cm -> {} voxels: best reused {best:?}, \
             one-shot (cold buffers) {one_shot_time:?}",
            out.len()
        );
        assert_eq!(out, one_shot);
        // Loose bound: the machine is shared; the budget is well under 1 ms.
        assert!(best < std::time::Duration::from_millis(20), "{best:?}");
    }
}
