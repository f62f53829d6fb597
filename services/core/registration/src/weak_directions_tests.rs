use super::*;

/// `Σ Jᵀ n nᵀ J` at the identity pose: each row `nᵀ J = [p × n; n]`.
fn information(points: &[(Vector3<f64>, Vector3<f64>)]) -> Matrix6<f64> {
    points.iter().fold(Matrix6::zeros(), |h, (p, n)| {
        let row = Vector6::new(0.0, 0.0, 0.0, n.x, n.y, n.z);
        let c = p.cross(n);
        let row = Vector6::new(c.x, c.y, c.z, row[3], row[4], row[5]);
        h + row * row.transpose()
    })
}

/// A grid of `k × k` points on the square `[-s, s]²` of the plane through
/// `centre` with normal `n` (spanned by `u`, `v`).
fn face(
    centre: Vector3<f64>,
    u: Vector3<f64>,
    v: Vector3<f64>,
    s: f64,
    k: usize,
) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let n = u.cross(&v).normalize();
    let step = 2.0 * s / (k - 1) as f64;
    (0..k * k)
        .map(|i| {
            let (a, b) = ((i % k) as f64 * step - s, (i / k) as f64 * step - s);
            (centre + u * a + v * b, n)
        })
        .collect()
}

/// Three faces of a cube of half-size `s` centred at the origin.
fn cube_corner(s: f64) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let (x, y, z) = (Vector3::x(), Vector3::y(), Vector3::z());
    let mut p = face(x * s, y, z, s, 9);
    p.extend(face(y * s, z, x, s, 9));
    p.extend(face(z * s, x, y, s, 9));
    p
}

#[test]
fn a_plane_leaves_its_two_shifts_and_its_spin_free() {
    let p = face(Vector3::zeros(), Vector3::x(), Vector3::y(), 1.0, 11);
    let h = information(&p);
    let r = rotations(&(h + Matrix6::identity() * 1e-9), p.len());
    assert!(r[0].per_point < 1e-6, "{r:?}");
    assert!(r[0].axis.z.abs() > 0.999, "{r:?}");
    let t = translations(&h, p.len(), &[]);
    assert!(t[0].per_point < 1e-12 && t[1].per_point < 1e-12, "{t:?}");
    assert!((t[2].per_point - 1.0).abs() < 1e-12);
    assert!(t[2].axis.z.abs() > 0.999);
}

#[test]
fn a_cube_corner_constrains_every_direction() {
    let p = cube_corner(1.0);
    let h = information(&p);
    let r = rotations(&h, p.len());
    let t = translations(&h, p.len(), &r.iter().map(|d| d.axis).collect::<Vec<_>>());
    assert_eq!((r.len(), t.len()), (3, 3));
    assert!(r[0].per_point > 0.1, "{r:?}");
    assert!(t[0].per_point > 0.1, "{t:?}");
}

#[test]
fn the_translation_figure_is_scale_free_and_the_rotation_figure_is_a_length() {
    let (small, large) = (
        information(&cube_corner(1.0)),
        information(&cube_corner(10.0)),
    );
    let n = cube_corner(1.0).len();
    let kept = |h: &Matrix6<f64>| rotations(h, n).iter().map(|d| d.axis).collect::<Vec<_>>();
    let (ts, tl) = (
        translations(&small, n, &kept(&small)),
        translations(&large, n, &kept(&large)),
    );
    for (a, b) in ts.iter().zip(&tl) {
        assert!((a.per_point - b.per_point).abs() < 1e-9, "{ts:?} {tl:?}");
    }
    let (rs, rl) = (rotations(&small, n), rotations(&large, n));
    for (a, b) in rs.iter().zip(&rl) {
        assert!((b.per_point / a.per_point - 100.0).abs() < 1e-6);
    }
}

/// A face seen head-on from far away, with a small side face: the shift
/// across the line of sight is weak only once the turn is free.
fn far_face() -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let mut p = face(Vector3::zeros(), Vector3::x(), Vector3::y(), 1.0, 11);
    p.extend(face(
        Vector3::new(1.0, 0.0, -0.1),
        Vector3::y(),
        Vector3::z(),
        0.1,
        3,
    ));
    p.extend(face(
        Vector3::new(0.0, 1.0, -0.1),
        Vector3::z(),
        Vector3::x(),
        0.1,
        3,
    ));
    p
}

#[test]
fn a_held_translation_moves_with_the_turn_that_keeps_the_surface_fitted() {
    let p = far_face();
    let h = information(&p);
    let kept: Vec<Vector3<f64>> = rotations(&h, p.len()).iter().map(|d| d.axis).collect();
    let t = translations(&h, p.len(), &kept);
    let shift = translation_shift(&h, &kept, &t[0].axis);
    // Stationary in the kept rotations: no turn lowers the cost further.
    let gradient = h * shift;
    for a in &kept {
        assert!(
            a.dot(&gradient.fixed_rows::<3>(0)).abs() < 1e-9,
            "{gradient}"
        );
    }
    // And the cost per point of that move is the eigenvalue.
    let cost = shift.dot(&(h * shift)) / p.len() as f64;
    assert!((cost - t[0].per_point).abs() < 1e-9, "{cost} {t:?}");
}

#[test]
fn a_held_turn_moves_with_the_shift_that_keeps_the_surface_fitted() {
    let p = far_face();
    let h = information(&p);
    let r = rotations(&h, p.len());
    let turn = rotation_turn(&h, &r[0].axis);
    let gradient = h * turn;
    assert!(gradient.fixed_rows::<3>(3).norm() < 1e-9, "{gradient}");
    let cost = turn.dot(&(h * turn)) / p.len() as f64;
    assert!((cost - r[0].per_point).abs() < 1e-9);
}

#[test]
fn held_lists_the_counts_asked_for_weakest_first() {
    let p = far_face();
    let h = information(&p);
    assert_eq!(
        Held::of(&h, 0, 0),
        Held {
            rotations: vec![],
            kept_rotations: rotations(&h, 1).iter().map(|d| d.axis).collect(),
            translations: vec![],
        }
    );
    let held = Held::of(&h, 1, 1);
    assert_eq!((held.rotations.len(), held.kept_rotations.len()), (1, 2));
    assert_eq!(held.translations.len(), 1);
    assert_eq!(held.rotations[0], rotations(&h, 1)[0].axis);
    let moves = held.moves(&h);
    assert_eq!(moves.len(), 2);
    // The translation's move turns about the kept rotations only.
    assert!(held.rotations[0].dot(&moves[1].fixed_rows::<3>(0)).abs() < 1e-9);
}
