//! Target packages end to end: the committed built-in packages match the
//! code, a mesh is prepared once into the cache and reloaded, an edited
//! mesh is prepared again, and a package refuses a scale.

use spacepose_model::Target;
use spacepose_model::package::{Geometry, load_package};
use spacepose_prepare::{builtin_package, resolve, resolve_in};
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(
        &std::env::var("CARGO_MANIFEST_DIR")
            .unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").to_owned()),
    )
    .join("../../..")
}

/// An ASCII STL of an axis-aligned box (half extents in file units).
fn box_stl(h: [f64; 3]) -> String {
    let c = |i: usize| {
        [
            if i & 1 == 0 { -h[0] } else { h[0] },
            if i & 2 == 0 { -h[1] } else { h[1] },
            if i & 4 == 0 { -h[2] } else { h[2] },
        ]
    };
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut s = String::from("solid box\n");
    for q in quads {
        for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            s += "facet normal 0 0 0\nouter loop\n";
            for i in t {
                let p = c(i);
                s += &format!("vertex {} {} {}\n", p[0], p[1], p[2]);
            }
            s += "endloop\nendfacet\n";
        }
    }
    s + "endsolid box\n"
}

#[test]
fn the_committed_builtin_packages_match_the_code() {
    for name in Target::BUILTIN {
        let dir = repo().join("deploy/targets").join(name);
        let committed = load_package(&dir).expect("the committed package loads");
        let code = Target::builtin(name).expect("built in");
        assert_eq!(
            committed.target.mesh().vertices(),
            code.mesh().vertices(),
            "{name}"
        );
        assert_eq!(committed.target.materials(), code.materials(), "{name}");
        assert_eq!(
            committed.manifest.geometry,
            Geometry::of(code.mesh()),
            "{name}"
        );
        let embedded = builtin_package(name, 1.0)
            .expect("embedded")
            .expect("a built-in");
        assert_eq!(
            embedded.manifest, committed.manifest,
            "{name}: rebuild the binary"
        );
    }
    // deos's detected group is the declared one (seed 004 §III.C.4).
    let deos = resolve("deos", 1.0).expect("deos");
    assert_eq!(deos.manifest.symmetry.source, "detected");
    assert_eq!(deos.target.symmetries().len(), 3);
    for declared in spacepose_model::builtin::deos::symmetries() {
        let found = deos
            .target
            .symmetries()
            .iter()
            .any(|s| s.angle_to(&declared) < 1e-6);
        assert!(
            found,
            "Rx({:.0}°) not detected",
            declared.angle().to_degrees()
        );
    }
}

#[test]
fn a_mesh_is_prepared_once_into_the_cache_and_again_when_edited() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mesh = dir.path().join("crate.stl");
    std::fs::write(&mesh, box_stl([500.0, 300.0, 150.0])).expect("write");
    let cache = dir.path().join("cache");
    let spec = mesh.to_str().expect("utf-8");
    let first = resolve_in(spec, 0.001, &cache).expect("prepared");
    let entry = first.dir.clone().expect("cached in a directory");
    assert!(entry.starts_with(&cache));
    let g = &first.manifest.geometry;
    assert!((g.extent_m[0] - 1.0).abs() < 1e-9 && (g.extent_m[2] - 0.3).abs() < 1e-9);
    assert_eq!(
        first.target.symmetries().len(),
        4,
        "a box's group: I and three half-turns"
    );
    let c = &first.manifest.calibration;
    assert!(c.max_mean_cost_ndt > c.record.mean_cost_p99);
    assert!(c.record.frames_used >= 20);

    let again = resolve_in(spec, 0.001, &cache).expect("loaded");
    assert_eq!(again.dir.as_ref(), Some(&entry));
    assert_eq!(again.manifest, first.manifest, "loaded, not prepared again");

    std::fs::write(&mesh, box_stl([500.0, 300.0, 200.0])).expect("edit");
    let edited = resolve_in(spec, 0.001, &cache).expect("prepared again");
    assert_ne!(edited.dir.as_ref(), Some(&entry));
    assert!((edited.manifest.geometry.extent_m[2] - 0.4).abs() < 1e-9);

    let e = resolve_in(entry.to_str().expect("utf-8"), 2.0, &cache).expect_err("scale");
    assert!(e.to_string().contains("already in metres"), "{e}");
}
