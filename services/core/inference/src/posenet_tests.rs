use crate::test_fixtures::{TOLERANCE, expected, fixture, max_abs_diff, tiny, tiny_shape};

use super::*;

fn load_tract(path: &Path, expect: ModelShape) -> Result<PoseNet, InferenceError> {
    PoseNet::load(path, Engine::Tract, expect)
}

#[test]
fn tract_reproduces_onnxruntime() {
    let expected = expected();
    assert_eq!(expected.cases.len(), 3);
    let mut net = load_tract(&tiny(), tiny_shape()).unwrap();
    assert_eq!(net.engine(), "tract");
    for case in &expected.cases {
        // Twice: the kept run state must not leak between calls.
        for _ in 0..2 {
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
}

#[test]
fn image_size_mismatch_is_a_load_error() {
    let expect = ModelShape {
        image_size: 32,
        ..tiny_shape()
    };
    let err = load_tract(&tiny(), expect).unwrap_err();
    assert!(
        matches!(err, InferenceError::ImageSizeMismatch { expected: 32, .. }),
        "{err}"
    );
    let text = err.to_string();
    assert!(
        text.contains("tiny_posenet.onnx") && text.contains("[1, 1, 16, 16]"),
        "{text}"
    );
}

#[test]
fn class_count_mismatch_is_a_load_error() {
    let expect = ModelShape {
        classes: 12,
        ..tiny_shape()
    };
    let err = load_tract(&tiny(), expect).unwrap_err();
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
    assert!(err.to_string().contains("tiny_posenet.onnx"), "{err}");
}

#[test]
fn wrong_outputs_are_load_errors() {
    let err = load_tract(&fixture("bad_output_names.onnx"), tiny_shape()).unwrap_err();
    assert!(
        matches!(err, InferenceError::OutputMismatch { .. }),
        "{err}"
    );
    assert!(err.to_string().contains("logits"), "{err}");
    let err = load_tract(&fixture("bad_pos_shape.onnx"), tiny_shape()).unwrap_err();
    assert!(
        matches!(err, InferenceError::OutputMismatch { .. }),
        "{err}"
    );
    assert!(err.to_string().contains("[1, 2]"), "{err}");
    let err = load_tract(&fixture("no_softmax.onnx"), tiny_shape()).unwrap_err();
    assert!(err.to_string().contains("Softmax"), "{err}");
}

#[test]
fn missing_and_corrupt_files_are_load_errors() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("absent.onnx");
    let err = load_tract(&missing, tiny_shape()).unwrap_err();
    assert!(matches!(err, InferenceError::ModelNotFound { .. }), "{err}");
    assert!(err.to_string().contains("absent.onnx"));
    assert!(matches!(
        load_tract(dir.path(), tiny_shape()),
        Err(InferenceError::ModelNotFound { .. })
    ));

    let garbage = dir.path().join("garbage.onnx");
    std::fs::write(&garbage, b"this is not a protobuf \xff\xfe\x00 at all").unwrap();
    let err = load_tract(&garbage, tiny_shape()).unwrap_err();
    assert!(
        matches!(
            err,
            InferenceError::ModelInvalid {
                engine: "tract",
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("garbage.onnx"));

    let bytes = std::fs::read(tiny()).unwrap();
    let truncated = dir.path().join("truncated.onnx");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let err = load_tract(&truncated, tiny_shape()).unwrap_err();
    assert!(matches!(err, InferenceError::ModelInvalid { .. }), "{err}");

    let empty = dir.path().join("empty.onnx");
    std::fs::write(&empty, b"").unwrap();
    assert!(load_tract(&empty, tiny_shape()).is_err());
}

#[test]
fn bad_depth_images_are_infer_errors() {
    let mut net = load_tract(&tiny(), tiny_shape()).unwrap();
    let err = net.infer(&[0.5; 255]).unwrap_err();
    assert!(
        matches!(
            err,
            InferenceError::InputLength {
                expected: 256,
                found: 255,
                image_size: 16
            }
        ),
        "{err}"
    );
    assert!(net.infer(&[]).is_err());
    let mut depth = vec![0.5; 256];
    depth[3] = f32::INFINITY;
    assert!(matches!(
        net.infer(&depth),
        Err(InferenceError::NonFiniteInput { index: 3, .. })
    ));
    // Still usable afterwards.
    net.infer(&[0.5; 256]).unwrap();
}

#[test]
fn invalid_expected_shape_is_refused() {
    let expect = ModelShape {
        image_size: 0,
        classes: 10,
    };
    assert!(matches!(
        load_tract(&tiny(), expect),
        Err(InferenceError::InvalidExpectedShape { .. })
    ));
}

#[cfg(not(feature = "ort"))]
#[test]
fn ort_without_the_feature_says_how_to_rebuild() {
    let engine = Engine::Ort {
        library: fixture("libonnxruntime.so"),
    };
    let err = PoseNet::load(&tiny(), engine, tiny_shape()).unwrap_err();
    assert!(matches!(err, InferenceError::OrtNotCompiled));
    assert!(err.to_string().contains("--features ort"), "{err}");
}
