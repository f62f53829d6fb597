//! The CNN method in the chain (issue 6): tried first, template matching as
//! the fallback; a missing model is a clear build error; with the trained
//! `deos` model, held-out simulated frames are acquired by the CNN.

#![allow(clippy::unwrap_used)] // test helpers

use spacepose_cnn::{DatasetConfig, Generator};
use spacepose_geometry::so3;
use spacepose_init_node::{InitError, InitServiceConfig, MethodKind};
use spacepose_messages::{AcquisitionMethod, Name};
use spacepose_model::Target;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A directory of the cnn crate, from the manifest directory cargo gives
/// the test at run time.
fn cnn_dir(sub: &str) -> String {
    let root = std::env::var("CARGO_MANIFEST_DIR")
        .unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").to_owned());
    format!("{root}/../../core/cnn/{sub}")
}

fn config(model_dir: &str, methods: Vec<MethodKind>) -> InitServiceConfig {
    let mut config = InitServiceConfig {
        methods,
        ..InitServiceConfig::default()
    };
    config.cnn.model_dir = Some(PathBuf::from(model_dir));
    config.validate().unwrap();
    config
}

#[test]
fn a_missing_model_is_a_build_error_naming_the_directory() {
    let config = config("/nonexistent/deos", vec![MethodKind::Cnn]);
    match config.build_chain() {
        Err(InitError::Build { method, reason }) => {
            assert_eq!(method, "cnn");
            assert!(reason.contains("/nonexistent/deos"), "{reason}");
        }
        Err(e) => panic!("expected a build error, got {e}"),
        Ok(_) => panic!("a chain without a model"),
    }
}

#[test]
fn the_cnn_comes_first_and_a_sparse_frame_is_a_failure() {
    let config = config(
        &cnn_dir("fixtures/fixed_deos"),
        vec![MethodKind::Cnn, MethodKind::TemplateMatching],
    );
    let chain = config.build_chain().unwrap();
    assert_eq!(
        chain.methods(),
        vec![AcquisitionMethod::Cnn, AcquisitionMethod::TemplateMatching]
    );
    let sparse = vec![spacepose_geometry::Point::new(0.0, 0.0, 10.0, 1.0, 0.0); 5];
    let a = chain.acquire(&sparse);
    assert!(a.accepted().is_none());
    assert_eq!(a.to_wire(0, 0.0, Name::new("init").unwrap()).success, 0);
}

#[test]
fn held_out_frames_are_acquired_by_the_cnn() {
    let deos_model = cnn_dir("models/deos");
    if !Path::new(&deos_model).join("model.onnx").is_file() {
        println!("skipped: no trained model at {deos_model}/model.onnx");
        return;
    }
    let config = config(
        &deos_model,
        vec![MethodKind::Cnn, MethodKind::TemplateMatching],
    );
    let chain = config.build_chain().unwrap();
    let deos = Arc::new(Target::builtin("deos").unwrap());
    let generator = Generator::new(
        deos.clone(),
        DatasetConfig {
            seed: 1003,
            count: 3,
            image_size: 64,
            roll_step_deg: 20.0,
            min_points: spacepose_cnn::DEFAULT_MIN_POINTS,
        },
    )
    .unwrap();
    let mut by_cnn = 0;
    for k in 0..3 {
        let frame = generator.frame(k).unwrap();
        let a = chain.acquire(&frame.points);
        println!("frame {k}: {}", a.summary());
        let msg = a.to_wire(k, 0.0, Name::new("init").unwrap());
        if msg.success == 1 && msg.method == AcquisitionMethod::Cnn as u8 {
            let pose = msg.pose().unwrap();
            let truth = &frame.truth.t_sensor_target;
            let err_deg =
                so3::distance_sym(&pose.rotation, &truth.rotation, deos.symmetries()).to_degrees();
            let err_cm = (pose.translation - truth.translation).norm() * 100.0;
            println!("  {err_deg:.2} deg {err_cm:.1} cm");
            assert!(err_deg < 5.0 && err_cm < 15.0, "accepted a wrong pose");
            by_cnn += 1;
        }
    }
    assert!(by_cnn >= 2, "{by_cnn} of 3 frames acquired by the CNN");
}
