use super::*;
use crate::material::Material;
use crate::target::Target;
use std::io::Write;

/// Cube of side 2 (file units) centred at CENTER: 8 corners and 6 outward quads.
const CENTER: [f64; 3] = [10.0, -4.0, 6.0];
const SCALE: f64 = 0.5;

fn corners() -> Vec<[f64; 3]> {
    (0..8)
        .map(|i| {
            let s = |bit: i32| if i & bit == 0 { -1.0 } else { 1.0 };
            [CENTER[0] + s(1), CENTER[1] + s(2), CENTER[2] + s(4)]
        })
        .collect()
}

const QUADS: [[u32; 4]; 6] = [
    [0, 4, 6, 2],
    [1, 3, 7, 5],
    [0, 1, 5, 4],
    [2, 6, 7, 3],
    [0, 2, 3, 1],
    [4, 5, 7, 6],
];

fn write_file(dir: &tempfile::TempDir, name: &str, text: &str) -> std::path::PathBuf {
    let path = dir.path().join(name);
    let mut f = File::create(&path).unwrap();
    f.write_all(text.as_bytes()).unwrap();
    path
}

fn write_stl(dir: &tempfile::TempDir, name: &str, corners: &[[f64; 3]]) -> std::path::PathBuf {
    let v = |k: u32| {
        let c = corners[k as usize];
        stl_io::Vector::new([c[0] as f32, c[1] as f32, c[2] as f32])
    };
    let tris: Vec<stl_io::Triangle> = QUADS
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .map(|t| stl_io::Triangle {
            normal: stl_io::Vector::new([0.0, 0.0, 0.0]),
            vertices: t.map(v),
        })
        .collect();
    let path = dir.path().join(name);
    let mut f = File::create(&path).unwrap();
    stl_io::write_stl(&mut f, tris.iter()).unwrap();
    path
}

fn obj_text() -> String {
    let mut s = String::from("# cube\nmtllib missing.mtl\no cube\n");
    for c in corners() {
        s += &format!("v {} {} {}\n", c[0], c[1], c[2]);
    }
    for q in QUADS {
        s += &format!("f {} {} {} {}\n", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
    }
    s
}

fn ply_text() -> String {
    let mut s = String::from(
        "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n\
         property double z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n",
    );
    for c in corners() {
        s += &format!("{} {} {}\n", c[0], c[1], c[2]);
    }
    for q in QUADS {
        s += &format!("4 {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    s
}

/// The loaded cube: side 1 m, centred on the origin, one structure material.
fn check_cube(t: &Target) {
    let m = t.mesh();
    assert_eq!(m.triangle_count(), 12);
    assert!(
        (m.surface_area() - 6.0).abs() < 1e-9,
        "{}",
        m.surface_area()
    );
    assert!(m.area_weighted_centroid().norm() < 1e-9);
    assert!((t.bounding_radius() - 0.75f64.sqrt()).abs() < 1e-6);
    let hit = t
        .cast_ray(&Vector3::new(5.0, 0.1, -0.2), &-Vector3::x(), 10.0)
        .expect("hit");
    assert!((hit.distance - 4.5).abs() < 1e-6);
    assert!((hit.normal - Vector3::x()).norm() < 1e-9);
    assert_eq!(t.materials(), &[Material::default_structure()]);
    assert_eq!(t.symmetries().len(), 1);
}

#[test]
fn cube_round_trips_through_stl_obj_and_ply() {
    let dir = tempfile::tempdir().unwrap();
    let stl = write_stl(&dir, "cube.stl", &corners());
    let obj = write_file(&dir, "cube.obj", &obj_text());
    let ply = write_file(&dir, "cube.PLY", &ply_text());
    for path in [stl, obj, ply] {
        let t = Target::load(&path, SCALE).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(t.name(), "cube");
        check_cube(&t);
        // Unit scale: side 2, area 24.
        let raw = Target::load(&path, 1.0).unwrap();
        assert!((raw.mesh().surface_area() - 24.0).abs() < 1e-9);
        // resolve() falls back to a path.
        let r = Target::resolve(path.to_str().unwrap(), SCALE).unwrap();
        assert_eq!(r.mesh().triangle_count(), 12);
    }
}

#[test]
fn load_errors_name_the_path() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.stl");
    let e = Target::load(&missing, 1.0).unwrap_err();
    assert!(matches!(e, TargetError::Read { .. }));
    assert!(e.to_string().contains("missing.stl"));

    let txt = write_file(&dir, "cube.txt", "hello");
    let e = Target::load(&txt, 1.0).unwrap_err();
    assert!(matches!(e, TargetError::UnknownExtension { .. }));
    assert!(e.to_string().contains("cube.txt"));

    let ply = write_file(&dir, "cube.ply", &ply_text());
    for scale in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = Target::load(&ply, scale).unwrap_err();
        assert!(matches!(e, TargetError::InvalidScale { .. }));
        assert!(e.to_string().contains("cube.ply"));
    }

    let empty_obj = write_file(&dir, "empty.obj", "# nothing\n");
    let e = Target::load(&empty_obj, 1.0).unwrap_err();
    assert!(matches!(e, TargetError::InvalidFile { .. }), "{e}");
    assert!(e.to_string().contains("empty.obj"));

    let garbage = write_file(&dir, "garbage.ply", "not a ply file\n");
    let e = Target::load(&garbage, 1.0).unwrap_err();
    assert!(matches!(e, TargetError::Read { .. }), "{e}");
    assert!(e.to_string().contains("garbage.ply"));

    let mut nan = corners();
    nan[3][1] = f64::NAN;
    let nan_stl = write_stl(&dir, "nan.stl", &nan);
    let e = Target::load(&nan_stl, 1.0).unwrap_err();
    assert!(matches!(e, TargetError::InvalidFile { .. }), "{e}");
    assert!(e.to_string().contains("nan.stl"));

    let flat: Vec<[f64; 3]> = corners().iter().map(|c| [c[0], c[1], 0.0]).collect();
    let flat_ply = {
        let mut s = ply_text();
        for (a, b) in corners().iter().zip(&flat) {
            s = s.replacen(
                &format!("{} {} {}\n", a[0], a[1], a[2]),
                &format!("{} {} {}\n", b[0], b[1], b[2]),
                1,
            );
        }
        write_file(&dir, "flat.ply", &s)
    };
    // A cube squashed flat still has its top and bottom... but all in one plane: the four
    // side quads vanish, the two caps coincide. Area = 2 x 4 = 8 (file units).
    let t = Target::load(&flat_ply, 1.0).unwrap();
    assert!((t.mesh().surface_area() - 8.0).abs() < 1e-9);

    let point = write_file(
        &dir,
        "point.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
         1 1 1\n1 1 1\n1 1 1\n3 0 1 2\n",
    );
    let e = Target::load(&point, 1.0).unwrap_err();
    assert!(matches!(e, TargetError::InvalidFile { .. }), "{e}");
    assert!(e.to_string().contains("degenerate"));
}
