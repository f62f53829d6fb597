use std::time::Instant;

use nalgebra::{Rotation3, Unit, Vector3};

use super::group::angle_between;
use super::*;
use crate::Target;
use crate::builtin::deos;
use crate::shapes::regular_prism_x;

/// Two rotation sets are the same (same size, each expected rotation within
/// `tol` rad of a detected one).
fn assert_same_set(actual: &[Rotation3<f64>], expected: &[Rotation3<f64>], tol: f64) {
    let show = |s: &[Rotation3<f64>]| {
        s.iter()
            .map(|r| format!("{:?}", r.scaled_axis().map(f64::to_degrees).as_slice()))
            .collect::<Vec<_>>()
            .join(", ")
    };
    assert_eq!(
        actual.len(),
        expected.len(),
        "detected [{}], expected [{}]",
        show(actual),
        show(expected)
    );
    for e in expected {
        assert!(
            actual.iter().any(|a| angle_between(a, e) < tol),
            "{:?} missing from [{}]",
            e.scaled_axis().as_slice(),
            show(actual)
        );
    }
}

fn rot(axis: Vector3<f64>, deg: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Unit::new_normalize(axis), deg.to_radians())
}

/// The half-turns about the three axes and the identity: the group of a box
/// with three different side lengths.
fn box_group() -> Vec<Rotation3<f64>> {
    vec![
        Rotation3::identity(),
        rot(Vector3::x(), 180.0),
        rot(Vector3::y(), 180.0),
        rot(Vector3::z(), 180.0),
    ]
}

/// The mesh moved so that its area-weighted centroid (the centre of mass of
/// a loaded mesh) is the origin.
fn centred(mesh: Mesh) -> Mesh {
    let c = mesh.area_weighted_centroid();
    mesh.transformed(&Rotation3::identity(), &-c)
        .expect("translated mesh")
}

fn detect(name: &str, mesh: &Mesh) -> SymmetryReport {
    let start = Instant::now();
    let report = detect_symmetries(mesh, &SymmetryOptions::default()).expect("detection");
    println!(
        "{name}: {} triangles, detection {:.1} ms, group {}, twins {}, {} candidates \
         ({} scored beyond the first look), samples {:?}",
        mesh.triangle_count(),
        start.elapsed().as_secs_f64() * 1e3,
        report.group.len(),
        report.twins.len(),
        report.candidates.len(),
        report.candidates.iter().filter(|c| c.points > 256).count(),
        report.samples
    );
    for t in &report.twins {
        println!(
            "  twin {:?}°",
            t.scaled_axis().map(f64::to_degrees).as_slice()
        );
    }
    assert!(report.group[0].angle() < 1e-12, "identity first");
    report
}

/// Each triangle split into four, `times` times (same surface, more
/// vertices and triangles).
fn subdivided(mesh: &Mesh, times: u32) -> Mesh {
    let mut vertices = mesh.vertices().to_vec();
    let mut triangles = mesh.triangles().to_vec();
    let mut materials = mesh.face_materials().to_vec();
    for _ in 0..times {
        let mut next = Vec::with_capacity(4 * triangles.len());
        for t in &triangles {
            let base = vertices.len() as u32;
            for (a, b) in [(0, 1), (1, 2), (2, 0)] {
                let mid = 0.5 * (vertices[t[a] as usize] + vertices[t[b] as usize]);
                vertices.push(mid);
            }
            let [ab, bc, ca] = [base, base + 1, base + 2];
            next.extend([[t[0], ab, ca], [ab, t[1], bc], [ca, bc, t[2]], [ab, bc, ca]]);
        }
        materials = materials.iter().flat_map(|&m| [m; 4]).collect();
        triangles = next;
    }
    Mesh::new(vertices, triangles, materials).expect("subdivided mesh")
}

/// Deos group and twins: `{I, Rx(±120°)}` and the three classes of
/// `deos::twins()` (Rx(60°): bars on the empty edges; Ry(180°): tower at
/// the other end; both).
fn assert_deos(report: &SymmetryReport) {
    assert_same_set(&report.group, &deos::symmetries(), 1e-6);
    assert_eq!(report.twins.len(), 3, "one twin per class");
    for f in deos::twins() {
        let found = report.twins.iter().any(|t| {
            report
                .group
                .iter()
                .any(|g| angle_between(&(t * g), &f) < 1e-6)
        });
        assert!(found, "twin {:?} not found", f.scaled_axis().as_slice());
    }
}

#[test]
fn deos_group_is_the_120_degree_roll_and_its_twins_are_found() {
    let target = Target::builtin("deos").expect("deos");
    let report = detect("deos", target.mesh());
    assert_deos(&report);
    // The class of Rx(60°): Rx(±60°) and Rx(180°) = Rx(60°) Rx(120°).
    let class: Vec<_> = report
        .candidates
        .iter()
        .filter(|s| {
            let a = s.angle_deg.abs();
            (s.axis.x.abs() - 1.0).abs() < 1e-9 && ((a - 60.0).abs() < 1e-9 || a > 180.0 - 1e-9)
        })
        .collect();
    assert_eq!(class.len(), 3, "Rx(±60°) and Rx(180°) are candidates");
    for s in &class {
        println!("  {s:?}");
        assert!(s.max_error_m > 0.03, "bars move off: {s:?}");
        assert!(s.median_error_m < 1e-5, "the rest maps onto itself: {s:?}");
    }
    // One is listed, the others are in its class.
    let verdicts: Vec<_> = class.iter().map(|s| s.verdict).collect();
    assert_eq!(
        verdicts.iter().filter(|&&v| v == Verdict::Twin).count(),
        1,
        "{verdicts:?}"
    );
    assert!(
        verdicts
            .iter()
            .all(|v| matches!(v, Verdict::Twin | Verdict::Covered))
    );
}

#[test]
fn deos_subdivided_to_64k_triangles_gives_the_same_result() {
    let target = Target::builtin("deos").expect("deos");
    let mesh = subdivided(target.mesh(), 4);
    assert_eq!(mesh.triangle_count(), 252 * 256);
    assert_deos(&detect("deos x256", &mesh));
}

#[test]
fn deos_scaled_and_rotated_gives_the_conjugated_group_and_twins() {
    let q = Rotation3::from_euler_angles(1.0, -0.4, 2.5);
    let mesh = Target::builtin("deos")
        .expect("deos")
        .mesh()
        .scaled(10.0)
        .expect("scaled")
        .transformed(&q, &Vector3::zeros())
        .expect("rotated");
    let report = detect("deos x10, rotated", &mesh);
    let conj = |r: &Rotation3<f64>| q * r * q.inverse();
    let group: Vec<_> = deos::symmetries().iter().map(conj).collect();
    assert_same_set(&report.group, &group, 1e-6);
    assert_eq!(report.twins.len(), 3);
    for f in deos::twins().iter().map(conj) {
        assert!(
            report
                .twins
                .iter()
                .any(|t| group.iter().any(|g| angle_between(&(t * g), &f) < 1e-6))
        );
    }
}

#[test]
fn deos_result_does_not_depend_on_the_seed() {
    let target = Target::builtin("deos").expect("deos");
    for seed in 2..=6 {
        let options = SymmetryOptions {
            seed,
            ..SymmetryOptions::default()
        };
        let report = detect_symmetries(target.mesh(), &options).expect("detection");
        assert_deos(&report);
    }
}

/// A 64-sided prism is within the tolerance of every rotation about its
/// axis. Its exact group D64 has elements of order 64; the detected group
/// is the largest of its subgroups whose orders stay within `max_order` =
/// 12: D8 (rotations by multiples of 45° and eight half-turns about axes
/// 22.5° apart, each through a vertex or the middle of a side).
#[test]
fn near_continuous_symmetry_gives_a_finite_group() {
    let mesh = regular_prism_x(64, 1.0, -1.5, 1.5, 0.0, 0, 0).expect("prism");
    let report = detect("64-gon prism", &mesh);
    assert_eq!(report.group.len(), 16);
    let about_x = |deg: f64| rot(Vector3::x(), deg);
    for k in 0..8 {
        let r = about_x(45.0 * f64::from(k));
        assert!(report.group.iter().any(|g| angle_between(g, &r) < 1e-6));
    }
    let step = 180.0 / 64.0;
    let half_turns: Vec<_> = report
        .group
        .iter()
        .filter(|g| g.angle() > std::f64::consts::PI - 1e-6)
        .map(super::group::rotation_axis)
        .filter(|u| u.x.abs() < 1e-9)
        .map(|u| u.z.atan2(u.y).to_degrees().rem_euclid(180.0))
        .collect();
    assert_eq!(half_turns.len(), 8, "{half_turns:?}");
    for a in &half_turns {
        let k = a / step;
        assert!((k - k.round()).abs() < 1e-6, "{a}° is no symmetry axis");
        let spaced = (a - half_turns[0]).rem_euclid(22.5);
        assert!(!(1e-6..=22.5 - 1e-6).contains(&spaced), "{half_turns:?}");
    }
    assert!(report.twins.is_empty());
}

#[test]
fn box_with_three_different_sides_has_the_four_element_group() {
    let mesh = Mesh::cuboid(
        Vector3::zeros(),
        Vector3::new(1.0, 0.6, 0.3),
        Rotation3::identity(),
        0,
    );
    let report = detect("box", &mesh);
    assert_same_set(&report.group, &box_group(), 1e-6);
    assert!(report.twins.is_empty(), "{:?}", report.twins);
}

#[test]
fn rotated_box_gives_the_conjugated_group() {
    let q = Rotation3::from_euler_angles(0.3, -0.7, 1.1);
    let mesh = Mesh::cuboid(
        Vector3::zeros(),
        Vector3::new(1.0, 0.6, 0.3),
        Rotation3::identity(),
        0,
    )
    .transformed(&q, &Vector3::zeros())
    .expect("rotated box");
    let report = detect("rotated box", &mesh);
    let expected: Vec<_> = box_group().iter().map(|s| q * s * q.inverse()).collect();
    assert_same_set(&report.group, &expected, 1e-6);
    // Not the axis-aligned group: the detection followed the mesh.
    assert!(angle_between(&report.group[1], &box_group()[1]) > 0.1);
}

/// A 24-sided cylinder along x with two identical flat panels on ±y and a
/// box antenna on the +x end, centred on the axis. Rx(180°) swaps the
/// panels and maps the cylinder and the antenna onto themselves. Any other
/// rotation about x moves the panels (Rx(90°) puts them on ±z). Ry(180°)
/// and Rz(180°) would also swap the panels, but they put the antenna on the
/// −x end, which is empty: they are twins (one class, since Rz(180°) =
/// Ry(180°) Rx(180°)), not symmetries. The origin is the area-weighted
/// centroid, off the cylinder's centre along x because of the antenna.
fn cylinder_with_two_panels() -> Mesh {
    let cylinder = regular_prism_x(24, 0.6, -1.0, 1.0, 0.0, 0, 0).expect("cylinder");
    let panel = |side: f64| {
        Mesh::cuboid(
            Vector3::new(0.0, side * 1.6, 0.0),
            Vector3::new(0.4, 1.0, 0.02),
            Rotation3::identity(),
            1,
        )
    };
    let antenna = Mesh::cuboid(
        Vector3::new(1.15, 0.0, 0.0),
        Vector3::new(0.15, 0.2, 0.1),
        Rotation3::identity(),
        0,
    );
    centred(Mesh::merged(&[cylinder, panel(1.0), panel(-1.0), antenna]).expect("merged"))
}

#[test]
fn cylinder_with_two_panels_is_two_fold() {
    let report = detect("cylinder + panels", &cylinder_with_two_panels());
    let rx180 = rot(Vector3::x(), 180.0);
    assert_same_set(&report.group, &[Rotation3::identity(), rx180], 1e-6);
    assert_eq!(report.twins.len(), 1);
    let ry180 = rot(Vector3::y(), 180.0);
    let t = report.twins[0];
    assert!(
        angle_between(&t, &ry180) < 1e-6 || angle_between(&(t * rx180), &ry180) < 1e-6,
        "{:?}",
        t.scaled_axis().as_slice()
    );
}

/// Boxes of different sizes at irregular offsets, one of them tilted.
fn asymmetric_assembly() -> Mesh {
    let part = |c: [f64; 3], h: [f64; 3], r: Rotation3<f64>| {
        Mesh::cuboid(Vector3::from(c), Vector3::from(h), r, 0)
    };
    let id = Rotation3::identity();
    centred(
        Mesh::merged(&[
            part([0.0, 0.0, 0.0], [0.8, 0.5, 0.4], id),
            part([1.1, 0.3, -0.2], [0.3, 0.2, 0.15], id),
            part(
                [-0.4, 0.7, 0.5],
                [0.2, 0.25, 0.1],
                Rotation3::from_euler_angles(0.2, 0.1, 0.4),
            ),
            part([0.2, -0.6, 0.45], [0.1, 0.1, 0.3], id),
        ])
        .expect("merged"),
    )
}

#[test]
fn asymmetric_assembly_has_the_identity_only() {
    let report = detect("asymmetric assembly", &asymmetric_assembly());
    assert_eq!(report.group.len(), 1);
    assert!(!report.candidates.is_empty());
    let false_symmetries: Vec<_> = report
        .candidates
        .iter()
        .filter(|c| c.verdict == Verdict::Symmetry)
        .collect();
    assert!(false_symmetries.is_empty(), "{false_symmetries:?}");
    let best = report
        .candidates
        .iter()
        .map(|c| c.max_error_m)
        .fold(f64::INFINITY, f64::min);
    println!("  smallest max error of a candidate: {best:.3} m");
    assert!(best > 0.005 * report.bounding_radius_m);
}

#[test]
fn cube_has_the_24_rotations_of_the_octahedral_group() {
    let mesh = Mesh::cuboid(
        Vector3::zeros(),
        Vector3::new(0.5, 0.5, 0.5),
        Rotation3::from_euler_angles(0.4, 0.2, -0.3),
        0,
    );
    let report = detect("cube", &mesh);
    assert_eq!(report.group.len(), 24);
    let mut orders = [0usize; 5];
    for g in &report.group {
        let n = super::group::order_of(g, 12, 1e-6).expect("finite order") as usize;
        orders[n] += 1;
        assert!(angle_between(&report.group[0], g) < 1e-12 || n > 1);
    }
    // 1 identity, 9 half-turns, 8 third-turns, 6 quarter-turns.
    assert_eq!(orders, [0, 1, 9, 8, 6]);
}

#[test]
fn hexagonal_prism_has_the_dihedral_group_of_order_12() {
    let mesh = regular_prism_x(6, 0.9, -1.0, 1.0, 0.0, 0, 0).expect("prism");
    let report = detect("hexagonal prism", &mesh);
    let mut expected: Vec<_> = (0..6)
        .map(|k| rot(Vector3::x(), 60.0 * f64::from(k)))
        .collect();
    for k in 0..6 {
        let a = (30.0 * f64::from(k)).to_radians();
        expected.push(rot(Vector3::new(0.0, a.cos(), a.sin()), 180.0));
    }
    assert_same_set(&report.group, &expected, 1e-6);
    assert!(report.twins.is_empty());
}

#[test]
fn options_are_validated() {
    let ok = SymmetryOptions::default();
    assert!(ok.validate().is_ok());
    let bad = [
        SymmetryOptions {
            tolerance_fraction: f64::NAN,
            ..ok
        },
        SymmetryOptions {
            twin_fraction: f64::NAN,
            ..ok
        },
        SymmetryOptions {
            sample_spacing_fraction: f64::NAN,
            ..ok
        },
        SymmetryOptions {
            tolerance_fraction: 0.0,
            ..ok
        },
        SymmetryOptions {
            twin_fraction: 0.001,
            ..ok
        },
        SymmetryOptions {
            sample_spacing_fraction: f64::INFINITY,
            ..ok
        },
        SymmetryOptions { max_order: 1, ..ok },
        SymmetryOptions {
            max_samples: 10,
            ..ok
        },
    ];
    let mesh = Mesh::cuboid(
        Vector3::zeros(),
        Vector3::new(1.0, 0.6, 0.3),
        Rotation3::identity(),
        0,
    );
    for o in bad {
        assert!(
            matches!(o.validate(), Err(TargetError::InvalidSymmetryOptions(_))),
            "{o:?}"
        );
        assert!(detect_symmetries(&mesh, &o).is_err());
    }
}

/// Convex solid from its vertices: the triangles are the vertex triples at
/// mutual distance `edge` (true of the tetrahedron and the icosahedron).
fn regular_solid(vertices: Vec<Vector3<f64>>, edge: f64) -> Mesh {
    let n = vertices.len() as u32;
    let d = |a: u32, b: u32| (vertices[a as usize] - vertices[b as usize]).norm();
    let is_edge = |a: u32, b: u32| (d(a, b) - edge).abs() < 1e-9;
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                if is_edge(i, j) && is_edge(j, k) && is_edge(i, k) {
                    triangles.push([i, j, k]);
                }
            }
        }
    }
    let triangles = crate::mesh::orient_outward(&vertices, triangles, &Vector3::zeros());
    let materials = vec![0; triangles.len()];
    Mesh::new(vertices, triangles, materials).expect("solid")
}

/// Number of group elements of each order 1..=5.
fn order_counts(group: &[Rotation3<f64>]) -> [usize; 6] {
    let mut counts = [0; 6];
    for g in group {
        counts[super::group::order_of(g, 5, 1e-6).expect("order <= 5") as usize] += 1;
    }
    counts
}

#[test]
fn tetrahedron_and_icosahedron_have_their_rotation_groups() {
    let s = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
    let tetrahedron = regular_solid(
        vec![
            s(1.0, 1.0, 1.0),
            s(1.0, -1.0, -1.0),
            s(-1.0, 1.0, -1.0),
            s(-1.0, -1.0, 1.0),
        ],
        8f64.sqrt(),
    );
    assert_eq!(tetrahedron.triangle_count(), 4);
    let report = detect("tetrahedron", &tetrahedron);
    // Identity, 3 half-turns (edge midpoints), 8 third-turns (vertices).
    assert_eq!(order_counts(&report.group), [0, 1, 3, 8, 0, 0]);
    let phi = 0.5 * (1.0 + 5f64.sqrt());
    let mut vertices = Vec::new();
    for (a, b) in [(1.0, phi), (-1.0, phi), (1.0, -phi), (-1.0, -phi)] {
        vertices.extend([s(0.0, a, b), s(a, b, 0.0), s(b, 0.0, a)]);
    }
    let icosahedron = regular_solid(vertices, 2.0);
    assert_eq!(icosahedron.triangle_count(), 20);
    let report = detect("icosahedron", &icosahedron);
    // Identity, 15 half-turns, 20 third-turns, 24 fifth-turns.
    assert_eq!(order_counts(&report.group), [0, 1, 15, 20, 0, 24]);
    assert!(report.twins.is_empty());
}
