use std::path::{Path, PathBuf};

use crate::engine::{Engine, find_ort_library};
use crate::error::InferenceError;
use crate::posenet::PoseNet;
use crate::test_fixtures::{TOLERANCE, expected, fixture, max_abs_diff, tiny, tiny_shape};

/// The ONNX Runtime library, or `None` with the reason printed (test skipped).
fn library() -> Option<PathBuf> {
    match find_ort_library() {
        Ok(path) => Some(path),
        Err(e) => {
            eprintln!("SKIPPED (no ONNX Runtime library): {e}");
            None
        }
    }
}

fn load_ort(path: &Path, library: PathBuf) -> Result<PoseNet, InferenceError> {
    PoseNet::load(path, Engine::Ort { library }, tiny_shape())
}

#[test]
fn ort_reproduces_onnxruntime() {
    let Some(lib) = library() else { return };
    let mut net = load_ort(&tiny(), lib).unwrap();
    assert_eq!(net.engine(), "ort");
    for case in &expected().cases {
        let out = net.infer(&case.depth).unwrap();
        let dp = max_abs_diff(&out.probs, &case.probs);
        let dx = max_abs_diff(&out.pos_offset_m, &case.pos);
        assert!(
            dp <= TOLERANCE && dx <= TOLERANCE,
            "{}: probs {dp:e}, pos {dx:e}",
            case.name
        );
    }
}

#[test]
fn ort_mismatches_are_load_errors() {
    let Some(lib) = library() else { return };
    let engine = Engine::Ort {
        library: lib.clone(),
    };
    let bigger = crate::ModelShape {
        image_size: 32,
        ..tiny_shape()
    };
    let err = PoseNet::load(&tiny(), engine.clone(), bigger).unwrap_err();
    assert!(
        matches!(err, InferenceError::ImageSizeMismatch { expected: 32, .. }),
        "{err}"
    );
    let more = crate::ModelShape {
        classes: 12,
        ..tiny_shape()
    };
    let err = PoseNet::load(&tiny(), engine, more).unwrap_err();
    assert!(
        matches!(
            err,
            InferenceError::ClassCountMismatch {
                expected: 12,
                found: 10,
                ..
            }
        ),
        "{err}"
    );
    let err = load_ort(&fixture("bad_output_names.onnx"), lib.clone()).unwrap_err();
    assert!(
        matches!(err, InferenceError::OutputMismatch { .. }),
        "{err}"
    );
    let err = load_ort(&fixture("bad_pos_shape.onnx"), lib.clone()).unwrap_err();
    assert!(
        matches!(err, InferenceError::OutputMismatch { .. }),
        "{err}"
    );
    let err = load_ort(&fixture("no_softmax.onnx"), lib.clone()).unwrap_err();
    assert!(err.to_string().contains("Softmax"), "{err}");

    let dir = tempfile::tempdir().unwrap();
    let garbage = dir.path().join("garbage.onnx");
    std::fs::write(&garbage, b"not a model at all").unwrap();
    let err = load_ort(&garbage, lib.clone()).unwrap_err();
    assert!(
        matches!(err, InferenceError::ModelInvalid { engine: "ort", .. }),
        "{err}"
    );
    let err = load_ort(&dir.path().join("absent.onnx"), lib).unwrap_err();
    assert!(matches!(err, InferenceError::ModelNotFound { .. }), "{err}");
}

#[test]
fn ort_wrong_input_length_is_an_infer_error() {
    let Some(lib) = library() else { return };
    let mut net = load_ort(&tiny(), lib).unwrap();
    assert!(matches!(
        net.infer(&[0.0; 300]),
        Err(InferenceError::InputLength { .. })
    ));
}

#[test]
fn missing_library_is_an_error_before_ort_is_called() {
    let err = load_ort(
        &tiny(),
        PathBuf::from("/nonexistent/libonnxruntime.so.1.31.1"),
    )
    .unwrap_err();
    assert!(
        matches!(err, InferenceError::OrtLibraryNotFound { .. }),
        "{err}"
    );
    assert!(
        err.to_string()
            .contains("/nonexistent/libonnxruntime.so.1.31.1"),
        "{err}"
    );
}

#[test]
fn a_file_that_is_not_a_library_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let fake = dir.path().join("libonnxruntime.so.9.9.9");
    std::fs::write(&fake, b"not an ELF file").unwrap();
    let err = load_ort(&tiny(), fake).unwrap_err();
    // Load error, or a conflict if another test loaded the real library first.
    assert!(
        matches!(
            err,
            InferenceError::OrtLibraryLoad { .. } | InferenceError::OrtLibraryConflict { .. }
        ),
        "{err}"
    );
}
