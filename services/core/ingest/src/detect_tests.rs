use super::*;
use crate::background::extent;
use nalgebra::Vector2;

fn grid_points(origin: Vector3<f64>, u: Vector3<f64>, v: Vector3<f64>, n: usize) -> Vec<Point> {
    let mut out = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let x = origin + u * (i as f64 / n as f64) + v * (j as f64 / n as f64);
            out.push(Point::new(x.x as f32, x.y as f32, x.z as f32, 1.0, 0.0));
        }
    }
    out
}

/// A 2 m cube (radius 1.73 m) at 10 m on a column, above a 20 m floor
/// and before a 20 m wall.
fn facility() -> (Vec<Point>, Vec<Point>, Vector3<f64>) {
    let c = Vector3::new(0.0, 0.0, 10.0);
    let mut target = Vec::new();
    // The three faces the sensor sees of a cube turned about y.
    let (a, b) = (
        Vector3::new(1.41, 0.0, 1.41),
        Vector3::new(-1.41, 0.0, 1.41),
    );
    let down = Vector3::new(0.0, 2.0, 0.0);
    let corner = c + Vector3::new(0.0, -1.0, -1.41);
    target.extend(grid_points(corner, a, down, 40));
    target.extend(grid_points(corner, b, down, 40));
    let mut clutter = Vec::new();
    // Floor 2.5 m below the centre (sensor y points down), wall 6 m behind.
    clutter.extend(grid_points(
        Vector3::new(-10.0, 2.5, 2.0),
        Vector3::x() * 20.0,
        Vector3::z() * 14.0,
        120,
    ));
    clutter.extend(grid_points(
        Vector3::new(-10.0, -8.0, 16.0),
        Vector3::x() * 20.0,
        Vector3::y() * 10.5,
        120,
    ));
    // The arm: a 0.4 m column from the cube's underside to the floor.
    clutter.extend(grid_points(
        Vector3::new(-0.2, 1.0, 9.2),
        Vector3::x() * 0.4,
        Vector3::y() * 1.5,
        15,
    ));
    (target, clutter, c)
}

#[test]
fn floor_and_wall_go_and_the_target_stays() {
    let (target, clutter, centre) = facility();
    let all: Vec<Point> = target.iter().chain(&clutter).copied().collect();
    let radius = 3f64.sqrt();
    let d = detect(&all, radius, 0.25, &DetectConfig::default()).expect("a detection");
    assert_eq!(d.background.len(), 2, "floor and wall");
    let kept = |pts: &[Point]| pts.iter().filter(|p| d.contains(&p.position())).count();
    assert_eq!(kept(&target), target.len());
    // Only the top of the arm (inside the region) is left of the facility.
    assert!(
        kept(&clutter) <= 225,
        "{} of {}",
        kept(&clutter),
        clutter.len()
    );
    // The centre of the returns lies on the near side, within R of the centre.
    assert!((d.centre - centre).norm() < radius, "{:?}", d.centre);
}

#[test]
fn a_panel_smaller_than_the_target_is_not_background() {
    // A 3 m panel of a target of radius 2: it fits in the bounding sphere.
    let panel = grid_points(
        Vector3::new(-1.5, -0.5, 10.0),
        Vector3::x() * 3.0,
        Vector3::y() * 1.0,
        60,
    );
    let d = detect(&panel, 2.0, 0.25, &DetectConfig::default()).expect("a detection");
    assert!(d.background.is_empty());
    assert!(panel.iter().all(|p| d.contains(&p.position())));
}

#[test]
fn too_few_points_find_nothing_and_the_search_is_deterministic() {
    let few = grid_points(Vector3::new(0.0, 0.0, 10.0), Vector3::x(), Vector3::y(), 4);
    assert!(detect(&few, 1.0, 0.25, &DetectConfig::default()).is_none());
    let (target, clutter, _) = facility();
    let all: Vec<Point> = target.iter().chain(&clutter).copied().collect();
    let a = detect(&all, 1.7, 0.25, &DetectConfig::default()).unwrap();
    let b = detect(&all, 1.7, 0.25, &DetectConfig::default()).unwrap();
    assert_eq!(a.centre, b.centre);
    let mut nan = all.clone();
    nan[0].x = f32::NAN;
    assert!(detect(&nan, 1.7, 0.25, &DetectConfig::default()).is_some());
}

#[test]
fn the_extent_is_the_width_along_the_widest_direction() {
    let diagonal = [Vector2::new(0.0, 0.0), Vector2::new(3.0, 4.0)];
    let e = extent(diagonal.iter());
    assert!((0.98 * 5.0..=5.0 + 1e-12).contains(&e), "{e}");
}
