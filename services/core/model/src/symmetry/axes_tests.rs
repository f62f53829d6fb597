use std::f64::consts::PI;

use nalgebra::{Rotation3, Vector3};

use super::*;
use crate::shapes::regular_prism_x;

#[test]
fn second_moment_of_a_box_surface_matches_the_closed_form() {
    let h = Vector3::new(1.0, 0.6, 0.3);
    let mesh = Mesh::cuboid(Vector3::zeros(), h, Rotation3::identity(), 0);
    let m = second_moment(&mesh);
    // ∫ x² dA over the surface: the two faces x = ±a give 2·a²·(4bc); the
    // four others give (2a)³/12·... = 2·(2a)³/12·(2b) + 2·(2a)³/12·(2c).
    let (a, b, c) = (h.x, h.y, h.z);
    let xx = 2.0 * a * a * 4.0 * b * c + (2.0 * a).powi(3) / 12.0 * 2.0 * (2.0 * b + 2.0 * c);
    assert!((m[(0, 0)] - xx).abs() < 1e-12, "{} vs {xx}", m[(0, 0)]);
    assert!(m[(0, 1)].abs() < 1e-12 && m[(1, 2)].abs() < 1e-12);
    assert!(m[(0, 0)] > m[(1, 1)] && m[(1, 1)] > m[(2, 2)]);
}

#[test]
fn moments_are_classified_by_their_coincidences() {
    let id = Rotation3::identity();
    let cuboid = |h: Vector3<f64>| Mesh::cuboid(Vector3::zeros(), h, id, 0);
    let m = second_moment(&cuboid(Vector3::new(1.0, 0.6, 0.3)));
    assert!(matches!(classify_moments(&m, 0.1), Moments::Distinct(_)));
    let m = second_moment(&cuboid(Vector3::new(1.0, 0.3, 0.3)));
    match classify_moments(&m, 0.1) {
        Moments::Axial(axis) => assert!((axis.x.abs() - 1.0).abs() < 1e-12),
        other => panic!("{other:?}"),
    }
    let m = second_moment(&cuboid(Vector3::new(0.5, 0.5, 0.5)));
    assert!(matches!(classify_moments(&m, 0.1), Moments::Isotropic(_)));
}

#[test]
fn n_fold_angles_list_each_rotation_once() {
    let a = n_fold_angles(12);
    // Σ φ(n) for n = 2..=12.
    assert_eq!(a.len(), 45);
    assert!(a.iter().all(|&x| x > -PI && x <= PI && x != 0.0));
    for target in [PI, 2.0 * PI / 3.0, -2.0 * PI / 3.0, PI / 6.0, -PI / 6.0] {
        assert_eq!(a.iter().filter(|&&x| (x - target).abs() < 1e-12).count(), 1);
    }
    assert_eq!(n_fold_angles(2), vec![PI]);
}

#[test]
fn hexagonal_prism_in_plane_axes_include_vertex_and_edge_directions() {
    let mesh = regular_prism_x(6, 0.9, -1.0, 1.0, 0.0, 0, 0).expect("prism");
    let axis = Unit::new_normalize(Vector3::x());
    let lines = in_plane_axes(mesh.vertices(), &axis, 1.35, 0.005);
    assert!(lines.iter().all(|u| u.x.abs() < 1e-12));
    for k in 0..6 {
        let a = (30.0 * f64::from(k)).to_radians();
        let want = Vector3::new(0.0, a.cos(), a.sin());
        assert!(
            lines.iter().any(|u| u.cross(&want).norm() < 1e-12),
            "no axis at {}°",
            30 * k
        );
    }
    let candidates = candidate_rotations(&mesh, &Moments::Axial(axis), 6, 1.35, 0.005);
    // 1 + 2 + 2 + 4 + 2 angles about x, then the in-plane half-turns.
    assert_eq!(
        candidates.iter().filter(|c| c.axis.x.abs() > 0.99).count(),
        11
    );
    assert!(candidates.len() >= 17);
}

#[test]
fn farthest_directions_and_pair_sums_of_a_cube() {
    let mesh = Mesh::cuboid(
        Vector3::zeros(),
        Vector3::new(0.5, 0.5, 0.5),
        Rotation3::identity(),
        0,
    );
    let r = 0.75f64.sqrt();
    let far = farthest_directions(mesh.vertices(), r, 0.005);
    assert_eq!(far.len(), 8);
    let sums = distinct_lines(pair_sums(&far), &far);
    // 6 edge midpoints (3 lines... each line twice) and 3 face centres:
    // lines through edge midpoints (6) and face centres (3).
    assert_eq!(sums.len(), 9);
}
