//! `spacepose target` as a new user runs it: prepare their own mesh into a
//! package, show it, and use it where a target is expected.

use std::path::Path;
use std::process::{Command, Output};

fn spacepose(args: &[&str], cache: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_spacepose"))
        .args(args)
        .env("SPACEPOSE_CACHE_DIR", cache)
        .output()
        .expect("spawn spacepose")
}

fn text(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr)
}

/// An L-shaped assembly of two boxes in millimetres (no symmetry but the
/// identity: the short arm breaks every half-turn).
fn write_l_stl(path: &Path) {
    let boxes = [
        ([0.0, 0.0, 0.0], [800.0, 250.0, 250.0]),
        ([650.0, 500.0, 0.0], [150.0, 250.0, 150.0]),
    ];
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut s = String::from("solid l\n");
    for (c, h) in boxes {
        let corner =
            |i: usize| [0, 1, 2].map(|k| c[k] + if i >> k & 1 == 0 { -h[k] } else { h[k] });
        for q in quads {
            for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                s += "facet normal 0 0 0\nouter loop\n";
                for i in t {
                    let p = corner(i);
                    s += &format!("vertex {} {} {}\n", p[0], p[1], p[2]);
                }
                s += "endloop\nendfacet\n";
            }
        }
    }
    std::fs::write(path, s + "endsolid l\n").expect("writing the STL");
}

#[test]
fn a_users_mesh_becomes_a_package_that_commands_accept() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mesh = dir.path().join("bracket.stl");
    write_l_stl(&mesh);
    let pkg = dir.path().join("bracket");
    let cache = dir.path().join("cache");
    let args = [
        "target",
        "prepare",
        mesh.to_str().unwrap(),
        "--scale",
        "0.001",
    ];
    let o = spacepose(
        &[&args[..], &["--out", pkg.to_str().unwrap()]].concat(),
        &cache,
    );
    let out = text(&o);
    assert!(o.status.success(), "{out}");
    assert!(out.contains("symmetry (detected): 1 rotation(s)"), "{out}");
    assert!(out.contains("calibration: max_mean_cost_ndt"), "{out}");
    assert!(pkg.join("target.toml").is_file() && pkg.join("mesh.obj").is_file());

    let o = spacepose(&["target", "show", pkg.to_str().unwrap()], &cache);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("target bracket"), "{}", text(&o));

    // The package is a target for the simulator (and every service).
    let run = dir.path().join("run");
    let sim = [
        "sim",
        "--target",
        pkg.to_str().unwrap(),
        "--scenario",
        "random",
        "--frames",
        "2",
    ];
    let o = spacepose(
        &[&sim[..], &["--out", run.to_str().unwrap()]].concat(),
        &cache,
    );
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        !cache.exists(),
        "a package directory is used as it is, not prepared again"
    );
}

#[test]
fn the_symmetry_can_be_overridden_and_bad_input_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mesh = dir.path().join("bracket.stl");
    write_l_stl(&mesh);
    let cache = dir.path().join("cache");
    let pkg = dir.path().join("p");
    let (m, p) = (mesh.to_str().unwrap(), pkg.to_str().unwrap());
    let o = spacepose(
        &[
            "target",
            "prepare",
            m,
            "--scale",
            "0.001",
            "--symmetry",
            "180,0,0",
            "--out",
            p,
        ],
        &cache,
    );
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        text(&o).contains("symmetry (override): 2 rotation(s)"),
        "{}",
        text(&o)
    );

    let o = spacepose(
        &["target", "prepare", m, "--symmetry", "1,2", "--out", p],
        &cache,
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).contains("needs three numbers"), "{}", text(&o));
    let missing = dir.path().join("missing.stl");
    let o = spacepose(
        &["target", "prepare", missing.to_str().unwrap(), "--out", p],
        &cache,
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).contains("missing.stl"), "{}", text(&o));
}

#[test]
fn a_generated_design_is_a_package_and_zoo_n_names_it_anywhere() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cache = dir.path().join("cache");
    let pkg = dir.path().join("zoo3");
    let p = pkg.to_str().unwrap();
    // Design 3 (a development design): exactly 2-fold about x.
    let o = spacepose(&["target", "generate", "--seed", "3", "--out", p], &cache);
    assert!(o.status.success(), "{}", text(&o));
    let out = text(&o);
    assert!(
        out.contains("design: zoo-3 (generator v1, exactly 2-fold"),
        "{out}"
    );
    assert!(out.contains("symmetry (detected): 2 rotation(s)"), "{out}");
    // The spec zoo:3 gives the same package, prepared into the cache.
    let o = spacepose(&["target", "show", "zoo:3"], &cache);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("target zoo-3 (zoo:3:v1)"), "{}", text(&o));
    let o = spacepose(&["target", "show", "zoo:three"], &cache);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("`zoo:N`, N a seed"), "{}", text(&o));
}
