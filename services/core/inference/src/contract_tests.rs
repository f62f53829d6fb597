use std::path::Path;

use super::*;

const EXPECT: ModelShape = ModelShape {
    image_size: 16,
    classes: 10,
};

fn names(n: &[&str]) -> Vec<String> {
    n.iter().map(|s| (*s).to_owned()).collect()
}

fn input(dims: &[Dim]) -> Result<(), InferenceError> {
    check_input(
        Path::new("m.onnx"),
        &names(&["depth"]),
        true,
        "f32",
        dims,
        EXPECT,
    )
}

#[test]
fn input_accepts_exact_and_free_dims() {
    input(&[Some(1), Some(1), Some(16), Some(16)]).unwrap();
    input(&[None, Some(1), None, None]).unwrap();
}

#[test]
fn input_image_size_mismatch_names_both_sizes() {
    let err = input(&[Some(1), Some(1), Some(32), Some(32)]).unwrap_err();
    assert!(
        matches!(err, InferenceError::ImageSizeMismatch { expected: 16, .. }),
        "{err}"
    );
    let text = err.to_string();
    assert!(
        text.contains("m.onnx") && text.contains("[1, 1, 32, 32]") && text.contains("16"),
        "{text}"
    );
}

#[test]
fn input_rank_channels_name_and_type_are_checked() {
    assert!(matches!(
        input(&[Some(1), Some(16), Some(16)]),
        Err(InferenceError::InputMismatch { .. })
    ));
    assert!(matches!(
        input(&[Some(1), Some(3), Some(16), Some(16)]),
        Err(InferenceError::InputMismatch { .. })
    ));
    let dims = [Some(1), Some(1), Some(16), Some(16)];
    let p = Path::new("m.onnx");
    assert!(matches!(
        check_input(p, &names(&["image"]), true, "f32", &dims, EXPECT),
        Err(InferenceError::InputMismatch { .. })
    ));
    assert!(matches!(
        check_input(p, &names(&["depth", "extra"]), true, "f32", &dims, EXPECT),
        Err(InferenceError::InputMismatch { .. })
    ));
    let err = check_input(p, &names(&["depth"]), false, "f16", &dims, EXPECT).unwrap_err();
    assert!(err.to_string().contains("f16"), "{err}");
}

#[test]
fn outputs_are_found_by_name_in_any_order() {
    let p = Path::new("m.onnx");
    assert_eq!(find_outputs(p, &names(&["probs", "pos"])).unwrap(), (0, 1));
    assert_eq!(find_outputs(p, &names(&["pos", "probs"])).unwrap(), (1, 0));
    let err = find_outputs(p, &names(&["logits", "position"])).unwrap_err();
    assert!(err.to_string().contains("logits"), "{err}");
    assert!(find_outputs(p, &names(&["probs", "pos", "extra"])).is_err());
}

#[test]
fn output_dims_class_count_and_pos_shape() {
    let p = Path::new("m.onnx");
    check_output_dims(p, &[Some(1), Some(10)], &[Some(1), Some(3)], EXPECT).unwrap();
    check_output_dims(p, &[None, None], &[None, Some(3)], EXPECT).unwrap();
    let err = check_output_dims(p, &[Some(1), Some(12)], &[Some(1), Some(3)], EXPECT).unwrap_err();
    assert!(
        matches!(
            err,
            InferenceError::ClassCountMismatch {
                expected: 10,
                found: 12,
                ..
            }
        ),
        "{err}"
    );
    let err = check_output_dims(p, &[Some(1), Some(10)], &[Some(1), Some(2)], EXPECT).unwrap_err();
    assert!(
        matches!(err, InferenceError::OutputMismatch { .. }),
        "{err}"
    );
}

#[test]
fn run_outputs_are_checked() {
    let p = Path::new("m.onnx");
    let probs = vec![0.1; 10];
    let out = output_from_slices(p, &probs, &[0.5, -0.25, 1.0], EXPECT).unwrap();
    assert_eq!(out.pos_offset_m, [0.5, -0.25, 1.0]);
    check_softmax(p, &out).unwrap();
    assert!(output_from_slices(p, &probs[..9], &[0.0; 3], EXPECT).is_err());
    assert!(output_from_slices(p, &probs, &[0.0; 2], EXPECT).is_err());
    assert!(matches!(
        output_from_slices(p, &probs, &[0.0, f32::NAN, 0.0], EXPECT),
        Err(InferenceError::NonFiniteOutput { output: "pos", .. })
    ));
    let logits = NetOutput {
        probs: vec![2.0, -1.0, 0.5],
        pos_offset_m: [0.0; 3],
    };
    assert!(
        check_softmax(p, &logits)
            .unwrap_err()
            .to_string()
            .contains("Softmax")
    );
}

#[test]
fn depth_length_and_finiteness() {
    check_depth(&[0.5; 256], EXPECT).unwrap();
    assert!(matches!(
        check_depth(&[0.5; 255], EXPECT),
        Err(InferenceError::InputLength {
            expected: 256,
            found: 255,
            ..
        })
    ));
    let mut d = vec![0.0; 256];
    d[17] = f32::NAN;
    assert!(matches!(
        check_depth(&d, EXPECT),
        Err(InferenceError::NonFiniteInput { index: 17, .. })
    ));
}

#[test]
fn expected_shape_must_be_positive() {
    assert!(
        ModelShape {
            image_size: 0,
            classes: 3
        }
        .validate()
        .is_err()
    );
    assert!(
        ModelShape {
            image_size: 8,
            classes: 0
        }
        .validate()
        .is_err()
    );
    EXPECT.validate().unwrap();
}
