use super::*;
use crate::npy::read_f32;

fn generator(seed: u64, count: usize) -> Generator {
    let deos = Arc::new(Target::builtin("deos").unwrap());
    Generator::new(
        deos,
        DatasetConfig {
            seed,
            count,
            image_size: 64,
            roll_step_deg: 20.0,
            min_points: DEFAULT_MIN_POINTS,
        },
    )
    .unwrap()
}

#[test]
fn small_set_is_written_complete_and_deterministic_across_threads() {
    let g = generator(77, 6);
    let dir1 = tempfile::tempdir().unwrap();
    let dir2 = tempfile::tempdir().unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let done = std::sync::atomic::AtomicU64::new(0);
    let progress = |k: u64| {
        done.fetch_add(k, std::sync::atomic::Ordering::Relaxed);
    };
    one.install(|| g.write(dir1.path(), &progress)).unwrap();
    two.install(|| g.write(dir2.path(), &progress)).unwrap();
    assert_eq!(done.into_inner(), 12);
    for f in [
        "class_quaternions",
        "depth",
        "labels",
        "pos_offset",
        "attitude",
        "range_m",
    ] {
        let a = std::fs::read(dir1.path().join(format!("{f}.npy"))).unwrap();
        let b = std::fs::read(dir2.path().join(format!("{f}.npy"))).unwrap();
        assert_eq!(a, b, "{f}.npy differs between 1 and 2 threads");
    }
    let (shape, depth) = read_f32(&dir1.path().join("depth.npy")).unwrap();
    assert_eq!(shape, vec![6, 64, 64]);
    assert!(depth.iter().all(|v| (0.0..=1.0).contains(v)));
    let (shape, labels) = read_f32(&dir1.path().join("labels.npy")).unwrap();
    assert_eq!(shape, vec![6, 618]);
    for row in labels.chunks(618) {
        assert!((row.iter().sum::<f32>() - 1.0).abs() < 1e-4);
    }
    let (shape, pos) = read_f32(&dir1.path().join("pos_offset.npy")).unwrap();
    assert_eq!(shape, vec![6, 3]);
    assert!(pos.iter().all(|v| v.abs() < 2.0));
    let (shape, range) = read_f32(&dir1.path().join("range_m.npy")).unwrap();
    assert_eq!(shape, vec![6]);
    assert!(range.iter().all(|r| (2.5..=20.0).contains(r)));
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir1.path().join("meta.json")).unwrap())
            .unwrap();
    assert_eq!(meta["classes"], 618);
    assert_eq!(meta["image_size"], 64);
    assert_eq!(meta["roi_side_m"], 4.0);
    assert_eq!(meta["symmetry_order"], 3);
    assert_eq!(meta["count"], 6);
}

#[test]
fn a_sample_matches_its_truth() {
    let g = generator(5, 1);
    let s = g.sample(3).unwrap();
    assert!(s.points_in_roi >= DEFAULT_MIN_POINTS);
    assert_eq!(s.depth.len(), 64 * 64);
    let filled = s.depth.iter().filter(|&&v| v > 0.0).count();
    assert!(filled > 20, "{filled} pixels");
    // The label peaks near the truth attitude.
    let q = s.attitude;
    let r = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
        f64::from(q[0]),
        f64::from(q[1]),
        f64::from(q[2]),
        f64::from(q[3]),
    ))
    .to_rotation_matrix();
    let back = crate::decode(g.classes(), &s.labels, 50f64.to_radians()).unwrap();
    let err = spacepose_geometry::so3::distance_sym(&r, &back, g.classes().symmetries());
    assert!(err.to_degrees() < 2.0);
    assert_eq!(s, g.sample(3).unwrap(), "same index, same sample");
    assert_ne!(s.depth, g.sample(4).unwrap().depth);
}
