use super::*;
use crate::symmetry::{SymmetryOptions, detect_symmetries};

#[test]
fn a_seed_names_one_mesh() {
    let a = generate(17).expect("zoo 17");
    let b = generate(17).expect("zoo 17");
    assert_eq!(a.target.mesh().vertices(), b.target.mesh().vertices());
    assert_eq!(a.description, b.description);
    let c = generate(18).expect("zoo 18");
    assert_ne!(a.target.mesh().vertices(), c.target.mesh().vertices());
}

#[test]
fn every_design_is_a_valid_target_of_plausible_size() {
    let mut intents = [0; 3];
    for seed in 0..90 {
        let zoo = generate(seed).unwrap_or_else(|e| panic!("zoo {seed}: {e}"));
        let t = &zoo.target;
        let r = t.bounding_radius();
        // Bus of 1-8 m, wings spanning at most 30 m (plus a bus end).
        assert!((0.4..=17.0).contains(&r), "zoo {seed}: radius {r}");
        let centroid = t.mesh().area_weighted_centroid();
        assert!(
            centroid.norm() < 1e-9 * r.max(1.0),
            "zoo {seed}: {centroid}"
        );
        assert!(t.mesh().face_materials().iter().all(|&m| m < 4));
        assert!(zoo.description.starts_with(&format!("zoo-{seed} ")));
        intents[match zoo.intent {
            Intent::Exact { .. } => 0,
            Intent::Near { .. } => 1,
            Intent::Asymmetric => 2,
        }] += 1;
    }
    assert_eq!(intents, [30, 30, 30]);
}

/// The group detected from the mesh holds the designed turn (exact), or
/// is the identity alone with a twin near that turn (near), or the
/// identity alone (not symmetric).
#[test]
fn the_detected_group_matches_the_intent() {
    let options = SymmetryOptions::default();
    for seed in [0, 1, 2, 3, 4, 5, 6, 8] {
        let zoo = generate(seed).expect("zoo");
        let report = detect_symmetries(zoo.target.mesh(), &options).expect("detection");
        let about_x = |r: &Rotation3<f64>, fold: u32| {
            let angle = TAU / f64::from(fold);
            let turn = Rotation3::from_axis_angle(&Vector3::x_axis(), angle);
            // The box of a near design moves the centre of mass, which tilts
            // the twin's axis by a few degrees.
            let within = 5f64.to_radians();
            r.angle_to(&turn) < within || r.angle_to(&turn.inverse()) < within
        };
        let what = format!(
            "{}: group {}, twins {:?}, R {:.2} m",
            zoo.description,
            report.group.len(),
            report
                .twins
                .iter()
                .map(|t| t.scaled_axis().map(f64::to_degrees))
                .collect::<Vec<_>>(),
            report.bounding_radius_m
        );
        match zoo.intent {
            Intent::Exact { fold } => {
                assert!(report.group.iter().any(|r| about_x(r, fold)), "{what}");
            }
            Intent::Near { fold } => {
                assert_eq!(report.group.len(), 1, "{what}");
                assert!(report.twins.iter().any(|r| about_x(r, fold)), "{what}");
            }
            Intent::Asymmetric => assert_eq!(report.group.len(), 1, "{what}"),
        }
    }
}
