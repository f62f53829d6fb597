//! The committed fixtures (fixtures/make_fixture.py) and onnxruntime's outputs.

use std::path::PathBuf;

use serde::Deserialize;

use crate::contract::ModelShape;

/// Largest difference allowed from onnxruntime's outputs.
pub(crate) const TOLERANCE: f32 = 1e-5;

/// The file `name` under `fixtures/`, found from the manifest directory
/// cargo gives the test at run time (a test binary reused from a build in
/// another checkout would otherwise look in that checkout).
pub(crate) fn fixture(name: &str) -> PathBuf {
    PathBuf::from(
        std::env::var("CARGO_MANIFEST_DIR")
            .unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").to_owned()),
    )
    .join("fixtures")
    .join(name)
}

pub(crate) fn tiny() -> PathBuf {
    fixture("tiny_posenet.onnx")
}

#[derive(Debug, Deserialize)]
pub(crate) struct Case {
    pub name: String,
    pub depth: Vec<f32>,
    pub probs: Vec<f32>,
    pub pos: Vec<f32>,
}

#[derive(Debug, Deserialize)]
pub(crate) struct Expected {
    pub image_size: usize,
    pub classes: usize,
    pub cases: Vec<Case>,
}

pub(crate) fn expected() -> Expected {
    let text = std::fs::read_to_string(fixture("expected.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

pub(crate) fn tiny_shape() -> ModelShape {
    let e = expected();
    ModelShape {
        image_size: e.image_size,
        classes: e.classes,
    }
}

/// Largest absolute difference, asserting equal lengths.
pub(crate) fn max_abs_diff(a: &[f32], b: &[f32]) -> f32 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}
