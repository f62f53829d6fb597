use super::*;

fn deos() -> Target {
    Target::builtin("deos").unwrap()
}

fn none() -> AsBuilt {
    AsBuilt {
        relief_m: 0.0,
        appendages: 0,
        scale_sigma: 0.0,
        com_offset: 0.0,
        ..AsBuilt::default()
    }
}

#[test]
fn no_perturbation_is_the_nominal_mesh() {
    let nominal = deos();
    let same = none().apply(&nominal, 3).unwrap();
    assert_eq!(same.mesh().vertices(), nominal.mesh().vertices());
    assert_eq!(same.mesh().triangles(), nominal.mesh().triangles());
    assert_eq!(same.symmetries().len(), 1);
}

#[test]
fn one_seed_builds_one_target() {
    let nominal = deos();
    let a = AsBuilt::default().apply(&nominal, 7).unwrap();
    let b = AsBuilt::default().apply(&nominal, 7).unwrap();
    let c = AsBuilt::default().apply(&nominal, 8).unwrap();
    assert_eq!(a.mesh().vertices(), b.mesh().vertices());
    assert_ne!(a.mesh().vertices(), c.mesh().vertices());
}

/// The relief moves MLI vertices along their face's normal by about
/// `relief_m` (zero on the edges), and nothing else moves.
#[test]
fn the_relief_bulges_the_mli_faces_only() {
    let nominal = deos();
    let only_relief = AsBuilt {
        relief_m: 0.02,
        ..none()
    };
    let t = only_relief.apply(&nominal, 11).unwrap();
    assert!(t.mesh().triangle_count() > nominal.mesh().triangle_count());
    let offsets: Vec<f64> = t
        .mesh()
        .vertices()
        .iter()
        .map(|v| nominal.mesh().distance_to_surface(v))
        .collect();
    let moved: Vec<f64> = offsets.iter().copied().filter(|d| *d > 1e-6).collect();
    let rms = (moved.iter().map(|d| d * d).sum::<f64>() / moved.len() as f64).sqrt();
    assert!(
        offsets.iter().all(|d| *d < 8.0 * 0.02),
        "bounded by the waves"
    );
    assert!((0.003..0.03).contains(&rms), "rms {rms}");
}

#[test]
fn the_centre_of_mass_and_the_scale_move_as_drawn() {
    let nominal = deos();
    let r = nominal.bounding_radius();
    let shifted = AsBuilt {
        com_offset: 0.02,
        ..none()
    }
    .apply(&nominal, 5)
    .unwrap();
    let d: Vec<Vector3<f64>> = shifted
        .mesh()
        .vertices()
        .iter()
        .zip(nominal.mesh().vertices())
        .map(|(a, n)| n - a)
        .collect();
    assert!(d.iter().all(|x| (x - d[0]).norm() < 1e-9), "one shift");
    assert!((d[0].norm() - 0.02 * r).abs() < 1e-9);
    let scaled = AsBuilt {
        scale_sigma: 0.01,
        ..none()
    }
    .apply(&nominal, 5)
    .unwrap();
    for (a, n) in scaled
        .mesh()
        .vertices()
        .iter()
        .zip(nominal.mesh().vertices())
    {
        for i in 0..3 {
            if n[i].abs() > 0.1 {
                assert!((a[i] / n[i] - 1.0).abs() < 0.05, "{a:?} {n:?}");
            }
        }
    }
}

#[test]
fn appendages_stand_on_the_surface() {
    let nominal = deos();
    let t = AsBuilt {
        appendages: 3,
        ..none()
    }
    .apply(&nominal, 2)
    .unwrap();
    let n = nominal.mesh().triangle_count();
    assert_eq!(t.mesh().triangle_count(), n + 3 * 12);
    let r = nominal.bounding_radius();
    for v in &t.mesh().vertices()[nominal.mesh().vertices().len()..] {
        assert!(v.norm() < 1.25 * r, "{v:?}");
        assert!(nominal.mesh().distance_to_surface(v) < 0.11 * r);
    }
}

#[test]
fn bad_settings_are_refused() {
    let nominal = deos();
    for bad in [
        AsBuilt {
            relief_m: f64::NAN,
            ..AsBuilt::default()
        },
        AsBuilt {
            appendage_size: [0.2, 0.1],
            ..AsBuilt::default()
        },
        AsBuilt {
            com_offset: -0.1,
            ..AsBuilt::default()
        },
    ] {
        assert!(bad.apply(&nominal, 1).is_err());
    }
}
