use super::*;
use crate::Target;
use nalgebra::Vector3;

fn manifest_of(t: &Target) -> PackageManifest {
    PackageManifest::describe(
        t,
        MeshRecord {
            file: MESH_FILE.to_owned(),
            source: format!("builtin:{}", t.name()),
            source_scale: 1.0,
            origin_in_source_m: [0.0; 3],
            conventions: "test".to_owned(),
        },
        SymmetryRecord::of(t.symmetries(), t.twins(), "declared", 0.005),
        Calibration {
            max_mean_cost_ndt: 9.5,
            min_inlier_fraction: 0.25,
            length_unit_m: 0.075,
            record: CalibrationRecord {
                frames: 10,
                frames_used: 9,
                seeds: vec![1],
                ranges_m: vec![10.0],
                mean_cost_p50: 4.0,
                mean_cost_p99: 6.3,
                inlier_fraction_p01: 0.5,
                rule: "test".to_owned(),
            },
        },
        Provenance {
            spacepose_version: "test".to_owned(),
            command: "test".to_owned(),
            source_fnv64: "0".to_owned(),
            prepare_s: 0.0,
        },
    )
}

#[test]
fn a_package_reloads_bit_for_bit() {
    let deos = Target::builtin("deos").expect("deos");
    let dir = tempfile::tempdir().expect("tempdir");
    write_package(dir.path(), &deos, &manifest_of(&deos)).expect("write");
    assert!(is_package_dir(dir.path()));
    let p = load_package(dir.path()).expect("load");
    assert_eq!(p.manifest, manifest_of(&deos));
    assert_eq!(p.target.mesh().vertices(), deos.mesh().vertices());
    assert_eq!(p.target.mesh().triangles(), deos.mesh().triangles());
    assert_eq!(
        p.target.mesh().face_materials(),
        deos.mesh().face_materials()
    );
    assert_eq!(p.target.materials(), deos.materials());
    assert_eq!(p.target.symmetries().len(), 3);
    for (a, b) in p.target.symmetries().iter().zip(deos.symmetries()) {
        assert!(a.angle_to(b) < 1e-7, "{}", a.angle_to(b));
    }
    for (a, b) in p.target.twins().iter().zip(deos.twins()) {
        assert!(a.angle_to(b) < 1e-7, "{}", a.angle_to(b));
    }
    let g = &p.manifest.geometry;
    assert!((g.bounding_radius_m - deos.bounding_radius()).abs() < 1e-12);
    assert!(
        g.body_box_max_m[0] > 1.5 && g.body_box_max_m[0] < 1.61,
        "{g:?}"
    );
}

#[test]
fn bad_packages_are_refused_with_a_reason() {
    let deos = Target::builtin("deos").expect("deos");
    let dir = tempfile::tempdir().expect("tempdir");
    let mut m = manifest_of(&deos);
    write_package(dir.path(), &deos, &m).expect("write");
    m.format = 99;
    let text = toml::to_string(&m).expect("toml");
    std::fs::write(dir.path().join(MANIFEST_FILE), text).expect("write");
    let e = load_package(dir.path()).expect_err("format 99");
    assert!(e.to_string().contains("format 99"), "{e}");

    let mut m = manifest_of(&deos);
    m.calibration.max_mean_cost_ndt = f64::NAN;
    let text = toml::to_string(&m).expect("toml");
    std::fs::write(dir.path().join(MANIFEST_FILE), text).expect("write");
    let e = load_package(dir.path()).expect_err("NaN bound");
    assert!(e.to_string().contains("max_mean_cost_ndt"), "{e}");

    let text = toml::to_string(&manifest_of(&deos)).expect("toml") + "surprise = 1\n";
    std::fs::write(dir.path().join(MANIFEST_FILE), text).expect("write");
    assert!(load_package(dir.path()).is_err(), "unknown key accepted");
    assert!(!is_package_dir(&dir.path().join("nothing")));
}

#[test]
fn the_mesh_reader_names_the_bad_line() {
    use super::obj::from_obj;
    let ok = "v 0 0 0\nv 1 0 0\nv 0 1 0\no material_0\nf 1 2 3\n";
    let mesh = from_obj(ok).expect("ok");
    assert_eq!(mesh.vertices()[1], Vector3::new(1.0, 0.0, 0.0));
    let cases = [
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "line 4"),
        ("v 0 0\n", "line 1"),
        ("v 0 0 0\nvt 1 0\n", "line 2"),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\no material_0\nf 0 1 2\n",
            "line 5",
        ),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\no part\n", "line 4"),
    ];
    for (text, line) in cases {
        let e = from_obj(text).expect_err(text);
        assert!(e.to_string().contains(line), "{text:?}: {e}");
    }
}
