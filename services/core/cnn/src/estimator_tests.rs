use super::*;
use crate::dataset::{DEFAULT_MIN_POINTS, DatasetConfig, Generator};
use spacepose_geometry::so3;

/// The crate directory cargo gives the test at run time.
fn crate_dir() -> std::path::PathBuf {
    std::env::var("CARGO_MANIFEST_DIR")
        .unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").to_owned())
        .into()
}

fn fixture_dir() -> std::path::PathBuf {
    crate_dir().join("fixtures/fixed_deos")
}

fn deos_model_dir() -> std::path::PathBuf {
    crate_dir().join("models/deos")
}

fn deos() -> Arc<Target> {
    Arc::new(Target::builtin("deos").unwrap())
}

/// A copy of the fixture whose model.json is edited by `edit`.
fn fixture_copy(edit: impl FnOnce(&mut serde_json::Value)) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let src = fixture_dir();
    std::fs::copy(src.join("model.onnx"), dir.path().join("model.onnx")).unwrap();
    let mut meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(src.join("model.json")).unwrap()).unwrap();
    edit(&mut meta);
    std::fs::write(dir.path().join("model.json"), meta.to_string()).unwrap();
    dir
}

fn load(dir: &Path) -> Result<CnnEstimator, CnnError> {
    CnnEstimator::load_with(dir, Engine::Tract, deos(), EstimatorConfig::default())
}

/// Held-out frames of the training generator (seed never trained on).
fn held_out(seed: u64, count: u64) -> Vec<crate::dataset::GeneratedFrame> {
    let g = Generator::new(
        deos(),
        DatasetConfig {
            seed,
            count: count as usize,
            image_size: 64,
            roll_step_deg: 20.0,
            min_points: DEFAULT_MIN_POINTS,
        },
    )
    .unwrap();
    (0..count).map(|i| g.frame(i).unwrap()).collect()
}

#[test]
fn missing_directory_or_files_are_clear_errors() {
    let err = load(Path::new("/nonexistent/model/dir")).unwrap_err();
    assert!(matches!(err, CnnError::ModelDir { .. }), "{err}");
    let empty = tempfile::tempdir().unwrap();
    let err = load(empty.path()).unwrap_err();
    assert!(err.to_string().contains("model.onnx"), "{err}");
    // model.onnx without model.json.
    std::fs::copy(
        fixture_dir().join("model.onnx"),
        empty.path().join("model.onnx"),
    )
    .unwrap();
    let err = load(empty.path()).unwrap_err();
    assert!(err.to_string().contains("model.json"), "{err}");
    // A corrupt model.json.
    std::fs::write(empty.path().join("model.json"), "{ not json").unwrap();
    let err = load(empty.path()).unwrap_err();
    assert!(matches!(err, CnnError::ModelMeta { .. }), "{err}");
}

#[test]
fn mismatched_model_is_refused_naming_the_field() {
    for (field, value) in [
        ("classes", serde_json::json!(600)),
        ("roi_side_m", serde_json::json!(3.0)),
        ("roll_step_deg", serde_json::json!(30.0)),
        ("symmetry_order", serde_json::json!(1)),
        ("target", serde_json::json!("envisat")),
    ] {
        let dir = fixture_copy(|m| m[field] = value.clone());
        let err = load(dir.path()).unwrap_err();
        match &err {
            CnnError::ModelMismatch { field: f, .. } => assert_eq!(*f, field),
            other => panic!("{field}: expected a mismatch, got {other}"),
        }
    }
    // N = 96 in model.json but the ONNX takes 64x64: the network check refuses it.
    let dir = fixture_copy(|m| m["image_size"] = serde_json::json!(96));
    let err = load(dir.path()).unwrap_err();
    assert!(matches!(err, CnnError::Inference(_)), "{err}");
}

#[test]
fn sparse_and_all_nan_clouds_are_errors_and_a_frame_gives_consistent_figures() {
    let estimator = load(&fixture_dir()).unwrap();
    assert_eq!(estimator.classes().len(), 618);
    let frame = &held_out(1001, 1)[0];
    let sparse = &frame.points[..MIN_POINTS - 1];
    let err = estimator.estimate(sparse).unwrap_err();
    assert!(
        matches!(err, CnnError::TooFewPoints { valid: 19, .. }),
        "{err}"
    );
    let nan: Vec<Point> = frame
        .points
        .iter()
        .map(|p| Point::new(f32::NAN, p.y, p.z, p.intensity, p.t))
        .collect();
    let err = estimator.estimate(&nan).unwrap_err();
    assert!(
        matches!(err, CnnError::TooFewPoints { valid: 0, .. }),
        "{err}"
    );
    assert!(estimator.estimate(&[]).is_err());

    // The untrained fixture gives some pose: the figures must be coherent.
    let e = estimator.estimate(&frame.points).unwrap();
    assert_eq!(e.accepted, e.f_conv_m2 <= estimator.f_max_m2());
    assert_eq!(e.points, frame.points.len());
    let offset = e.t_sensor_target_raw.translation - frame.image.roi_centre;
    assert!(offset.amax() <= 2.0, "offset {offset:?} beyond l/2");
    let t = e.time_ms;
    assert!(t.preprocess > 0.0 && t.inference > 0.0 && t.refinement > 0.0);
    assert!(t.total >= t.preprocess + t.inference + t.refinement - 1e-6);
}

#[test]
fn real_model_acquires_held_out_frames() {
    if !deos_model_dir().join("model.onnx").is_file() {
        println!(
            "skipped: no trained model in {}",
            deos_model_dir().display()
        );
        return;
    }
    let estimator = load(&deos_model_dir()).unwrap();
    let frames = held_out(1002, 10);
    let mut ok = 0;
    for (i, f) in frames.iter().enumerate() {
        let e = estimator.estimate(&f.points).unwrap();
        let truth = &f.truth.t_sensor_target;
        let syms = estimator.classes().symmetries();
        let err_deg =
            so3::distance_sym(&e.t_sensor_target.rotation, &truth.rotation, syms).to_degrees();
        let err_cm = (e.t_sensor_target.translation - truth.translation).norm() * 100.0;
        println!(
            "frame {i}: {err_deg:.2} deg {err_cm:.1} cm f_conv {:.2e} accepted {}",
            e.f_conv_m2, e.accepted
        );
        if err_deg < 5.0 && err_cm < 15.0 {
            ok += 1;
        }
    }
    assert!(ok >= 9, "{ok}/10 held-out frames acquired");
}
