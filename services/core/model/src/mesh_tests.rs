use super::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Analytic first hit of a ray with an oriented box (slab method), with the entry normal
/// (outward, as seen from an outside origin). `None` on a miss or if the origin is inside.
/// Also returns the gap between the two largest slab entries (small = near an edge).
fn box_hit(
    center: &Vector3<f64>,
    half: &Vector3<f64>,
    rot: &Rotation3<f64>,
    origin: &Vector3<f64>,
    dir: &Vector3<f64>,
) -> Option<(f64, Vector3<f64>, f64)> {
    let o = rot.inverse() * (origin - center);
    let d = rot.inverse() * dir;
    let mut entries = [(f64::NEG_INFINITY, 0usize); 3];
    let mut t_exit = f64::INFINITY;
    for k in 0..3 {
        let t1 = (-half[k] - o[k]) / d[k];
        let t2 = (half[k] - o[k]) / d[k];
        entries[k] = (t1.min(t2), k);
        t_exit = t_exit.min(t1.max(t2));
    }
    entries.sort_by(|a, b| b.0.total_cmp(&a.0));
    let (t_enter, axis) = entries[0];
    if t_enter > t_exit || t_enter < 0.0 {
        return None;
    }
    let mut n = Vector3::zeros();
    n[axis] = -d[axis].signum();
    Some((t_enter, rot * n, t_enter - entries[1].0))
}

fn test_box() -> (Vector3<f64>, Vector3<f64>, Rotation3<f64>, Mesh) {
    let center = Vector3::new(1.0, -2.0, 3.0);
    let half = Vector3::new(1.5, 0.7, 0.4);
    let rot = Rotation3::from_euler_angles(0.3, -0.5, 1.1);
    let mesh = Mesh::cuboid(center, half, rot, 7);
    (center, half, rot, mesh)
}

#[test]
fn cuboid_geometry_is_right() {
    let (center, half, _, mesh) = test_box();
    assert_eq!(mesh.triangle_count(), 12);
    let area = 8.0 * (half.x * half.y + half.y * half.z + half.x * half.z);
    assert!((mesh.surface_area() - area).abs() < 1e-12);
    assert!((mesh.area_weighted_centroid() - center).norm() < 1e-12);
    // Outward normals.
    for (t, n) in mesh.triangles().iter().zip(mesh.face_normals()) {
        let c = t
            .iter()
            .fold(Vector3::zeros(), |s, &k| s + mesh.vertices()[k as usize])
            / 3.0;
        assert!(n.dot(&(c - center)) > 0.0);
    }
    let (sc, r) = mesh.bounding_sphere();
    assert!((sc - center).norm() < 1e-12);
    assert!((r - half.norm()).abs() < 1e-12);
}

#[test]
fn rays_hit_an_analytic_box_at_many_angles() {
    let (center, half, rot, mesh) = test_box();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut checked = 0;
    for _ in 0..2000 {
        // Origin on a sphere of radius 8 m around the box, aimed at a point inside it.
        let u = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        if u.norm() < 1e-3 {
            continue;
        }
        let origin = center + u.normalize() * 8.0;
        let inside = Vector3::new(
            rng.random_range(-0.95..0.95) * half.x,
            rng.random_range(-0.95..0.95) * half.y,
            rng.random_range(-0.95..0.95) * half.z,
        );
        let dir = (center + rot * inside - origin).normalize();
        let (t, n, gap) = box_hit(&center, &half, &rot, &origin, &dir).expect("aimed inside");
        let hit = mesh.cast_ray(&origin, &dir, 100.0).expect("must hit");
        assert!((hit.distance - t).abs() < 1e-5, "{} vs {t}", hit.distance);
        assert_eq!(hit.material, 7);
        if gap > 1e-6 {
            assert!((hit.normal - n).norm() < 1e-5, "{} vs {n}", hit.normal);
            checked += 1;
        }
        assert!(hit.normal.dot(&dir) < 0.0, "normal faces the origin");
    }
    assert!(checked > 1900);
}

#[test]
fn axis_aligned_rays_at_fixed_angles() {
    let mesh = Mesh::cuboid(
        Vector3::zeros(),
        Vector3::new(1.0, 1.0, 1.0),
        Rotation3::identity(),
        0,
    );
    for deg in [0.0_f64, 15.0, 30.0, 45.0, 60.0] {
        let a = deg.to_radians();
        // Aim at the point (1, 0, 0.3) of the +x face from 5 m away, tilted by `a` about z.
        let target = Vector3::new(1.0, 0.0, 0.3);
        let dir = Vector3::new(-a.cos(), -a.sin(), 0.0);
        let origin = target - dir * 5.0;
        let hit = mesh.cast_ray(&origin, &dir, 10.0).expect("hit");
        assert!((hit.distance - 5.0).abs() < 1e-9, "{deg}: {}", hit.distance);
        assert!((hit.normal - Vector3::x()).norm() < 1e-12);
    }
}

#[test]
fn rays_miss_when_they_should() {
    let (center, _, _, mesh) = test_box();
    let origin = center + Vector3::new(6.0, 0.0, 0.0);
    // Pointing away.
    assert!(mesh.cast_ray(&origin, &Vector3::x(), 100.0).is_none());
    // Passing beside (the box is within 1.7 m of its centre).
    let beside = Vector3::new(-1.0, 0.0, 0.0);
    let o2 = center + Vector3::new(6.0, 2.0, 0.0);
    assert!(mesh.cast_ray(&o2, &beside, 100.0).is_none());
    // Beyond max_range.
    let toward = (center + Vector3::new(0.1, 0.05, 0.02) - origin).normalize();
    let hit = mesh.cast_ray(&origin, &toward, 100.0).expect("hit");
    assert!(
        mesh.cast_ray(&origin, &toward, hit.distance - 1e-3)
            .is_none()
    );
    assert!(
        mesh.cast_ray(&origin, &toward, hit.distance + 1e-3)
            .is_some()
    );
    // Degenerate inputs.
    assert!(mesh.cast_ray(&origin, &Vector3::zeros(), 100.0).is_none());
    assert!(mesh.cast_ray(&origin, &toward, -1.0).is_none());
    assert!(mesh.cast_ray(&origin, &toward, f64::NAN).is_none());
    let nan = Vector3::new(f64::NAN, 0.0, 0.0);
    assert!(mesh.cast_ray(&nan, &toward, 100.0).is_none());
    assert!(mesh.cast_ray(&origin, &nan, 100.0).is_none());
}

#[test]
fn ray_from_inside_hits_the_wall_with_inward_normal() {
    let mesh = Mesh::cuboid(
        Vector3::zeros(),
        Vector3::new(2.0, 1.0, 1.0),
        Rotation3::identity(),
        0,
    );
    let hit = mesh
        .cast_ray(&Vector3::new(0.5, 0.3, -0.1), &Vector3::x(), 10.0)
        .expect("hit");
    assert!((hit.distance - 1.5).abs() < 1e-12);
    assert!((hit.normal + Vector3::x()).norm() < 1e-12);
}

#[test]
fn non_unit_direction_is_normalised() {
    let (center, _, _, mesh) = test_box();
    let origin = center + Vector3::new(0.1, 0.05, 9.0);
    let a = mesh.cast_ray(&origin, &-Vector3::z(), 100.0).expect("hit");
    let b = mesh
        .cast_ray(&origin, &(-Vector3::z() * 3.0), 100.0)
        .expect("hit");
    assert!((a.distance - b.distance).abs() < 1e-12);
}

#[test]
fn merged_keeps_materials_per_face() {
    let a = Mesh::cuboid(
        Vector3::zeros(),
        Vector3::new(1.0, 1.0, 1.0),
        Rotation3::identity(),
        1,
    );
    let b = Mesh::cuboid(
        Vector3::new(5.0, 0.0, 0.0),
        Vector3::new(1.0, 1.0, 1.0),
        Rotation3::identity(),
        2,
    );
    let m = Mesh::merged(&[a, b]).expect("merge");
    assert_eq!(m.triangle_count(), 24);
    assert!(m.face_materials()[..12].iter().all(|&k| k == 1));
    assert!(m.face_materials()[12..].iter().all(|&k| k == 2));
    let from_left = m
        .cast_ray(&Vector3::new(-10.0, 0.2, 0.1), &Vector3::x(), 100.0)
        .expect("hit");
    assert_eq!(from_left.material, 1);
    assert!((from_left.distance - 9.0).abs() < 1e-12);
    let from_right = m
        .cast_ray(&Vector3::new(10.0, 0.2, 0.1), &-Vector3::x(), 100.0)
        .expect("hit");
    assert_eq!(from_right.material, 2);
    assert!((from_right.distance - 4.0).abs() < 1e-12);
    assert!(from_right.face >= 12);
    assert!(Mesh::merged(&[]).is_err());
}

#[test]
fn new_rejects_bad_meshes() {
    let v = vec![Vector3::zeros(), Vector3::x(), Vector3::y()];
    assert!(Mesh::new(v.clone(), vec![[0, 1, 2]], vec![0]).is_ok());
    assert!(Mesh::new(vec![], vec![[0, 1, 2]], vec![0]).is_err());
    assert!(Mesh::new(v.clone(), vec![], vec![]).is_err());
    assert!(Mesh::new(v.clone(), vec![[0, 1, 3]], vec![0]).is_err());
    assert!(Mesh::new(v.clone(), vec![[0, 1, 2]], vec![]).is_err());
    assert!(Mesh::new(v.clone(), vec![[0, 1, 1]], vec![0]).is_err());
    let mut bad = v.clone();
    bad[1].y = f64::NAN;
    assert!(Mesh::new(bad, vec![[0, 1, 2]], vec![0]).is_err());
    let mut huge = v;
    huge[1].x = 1e300;
    assert!(Mesh::new(huge, vec![[0, 1, 2]], vec![0]).is_err());
    assert!(
        Mesh::try_cuboid(Vector3::zeros(), Vector3::zeros(), Rotation3::identity(), 0).is_err()
    );
}

#[test]
fn distance_to_surface_of_a_box() {
    let mesh = Mesh::cuboid(
        Vector3::zeros(),
        Vector3::new(1.0, 1.0, 1.0),
        Rotation3::identity(),
        0,
    );
    assert!((mesh.distance_to_surface(&Vector3::new(3.0, 0.2, 0.1)) - 2.0).abs() < 1e-6);
    assert!((mesh.distance_to_surface(&Vector3::new(0.5, 0.0, 0.0)) - 0.5).abs() < 1e-6);
    assert!(mesh.distance_to_surface(&Vector3::new(1.0, 0.3, -0.2)) < 1e-6);
}

#[test]
fn transformed_and_scaled() {
    let (_, half, _, mesh) = test_box();
    let s = mesh.scaled(2.0).expect("scale");
    assert!((s.surface_area() - 4.0 * mesh.surface_area()).abs() < 1e-9);
    assert!(mesh.scaled(0.0).is_err());
    assert!(mesh.scaled(f64::NAN).is_err());
    let back = mesh
        .transformed(&Rotation3::identity(), &-mesh.area_weighted_centroid())
        .expect("move");
    assert!(back.area_weighted_centroid().norm() < 1e-12);
    assert!((back.bounding_sphere().1 - half.norm()).abs() < 1e-12);
}
