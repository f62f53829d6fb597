//! The ONNX model contract (notes/acq-design.md) and its checks, shared by
//! every engine: input `depth` float32 [1, 1, N, N]; outputs `probs` float32
//! [1, m] (softmax over the attitude classes of seed 004 §III.C) and `pos`
//! float32 [1, 3] (metres, tanh × l/2: target origin minus ROI centre).

use std::path::Path;

use crate::error::InferenceError;

/// Name of the single model input.
pub const INPUT_NAME: &str = "depth";
/// Name of the class-probability output.
pub const PROBS_NAME: &str = "probs";
/// Name of the position-offset output.
pub const POS_NAME: &str = "pos";

/// How far the class probabilities of a zero image may sum away from 1 before
/// the load check decides the softmax is missing.
const SOFTMAX_SUM_TOLERANCE: f32 = 1e-3;

/// What the caller expects of the model: it must match the class table and
/// the preprocessing in use, or loading fails.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModelShape {
    /// Side N of the square depth image (seed 004 Eq. 3).
    pub image_size: usize,
    /// Number of attitude classes m.
    pub classes: usize,
}

impl ModelShape {
    /// Number of pixels N × N.
    pub fn pixels(&self) -> usize {
        self.image_size * self.image_size
    }

    pub(crate) fn validate(&self) -> Result<(), InferenceError> {
        if self.image_size == 0 || self.classes == 0 {
            return Err(InferenceError::InvalidExpectedShape {
                image_size: self.image_size,
                classes: self.classes,
            });
        }
        Ok(())
    }
}

/// One forward pass of the network.
#[derive(Debug, Clone, PartialEq)]
pub struct NetOutput {
    /// Class probabilities (softmax), length m.
    pub probs: Vec<f32>,
    /// Offset of the target origin from the ROI centre, sensor frame, metres.
    pub pos_offset_m: [f32; 3],
}

/// A dimension as a model declares it: `None` when symbolic or unknown.
pub(crate) type Dim = Option<i64>;

/// `[1, 1, ?, 16]`.
pub(crate) fn format_dims(dims: &[Dim]) -> String {
    let parts: Vec<String> = dims
        .iter()
        .map(|d| d.map_or_else(|| "?".to_owned(), |v| v.to_string()))
        .collect();
    format!("[{}]", parts.join(", "))
}

fn fits(dim: Dim, want: usize) -> bool {
    dim.is_none_or(|d| usize::try_from(d).is_ok_and(|d| d == want))
}

/// The declared input: exactly one, named `depth`, float32, [1, 1, N, N]
/// (free dimensions are accepted and fixed to the expected values).
pub(crate) fn check_input(
    path: &Path,
    names: &[String],
    is_f32: bool,
    dtype: &str,
    dims: &[Dim],
    expect: ModelShape,
) -> Result<(), InferenceError> {
    let mismatch = |expected: String, found: String| InferenceError::InputMismatch {
        path: path.to_path_buf(),
        expected,
        found,
    };
    if names.len() != 1 || names[0] != INPUT_NAME {
        return Err(mismatch(
            format!("one input named `{INPUT_NAME}`"),
            format!("inputs {names:?}"),
        ));
    }
    if !is_f32 {
        return Err(mismatch(
            format!("`{INPUT_NAME}` of type float32"),
            format!("type {dtype}"),
        ));
    }
    let found = format_dims(dims);
    if dims.len() != 4 || !fits(dims[0], 1) || !fits(dims[1], 1) {
        return Err(mismatch(
            format!("`{INPUT_NAME}` of shape [1, 1, N, N]"),
            format!("shape {found}"),
        ));
    }
    if !fits(dims[2], expect.image_size) || !fits(dims[3], expect.image_size) {
        return Err(InferenceError::ImageSizeMismatch {
            path: path.to_path_buf(),
            expected: expect.image_size,
            found,
        });
    }
    Ok(())
}

/// Indices of `probs` and `pos` among the model's outputs (exactly those two).
pub(crate) fn find_outputs(
    path: &Path,
    names: &[String],
) -> Result<(usize, usize), InferenceError> {
    let probs = names.iter().position(|n| n == PROBS_NAME);
    let pos = names.iter().position(|n| n == POS_NAME);
    match (probs, pos) {
        (Some(probs), Some(pos)) if names.len() == 2 => Ok((probs, pos)),
        _ => Err(InferenceError::OutputMismatch {
            path: path.to_path_buf(),
            expected: format!("two outputs named `{PROBS_NAME}` and `{POS_NAME}`"),
            found: format!("outputs {names:?}"),
        }),
    }
}

/// `probs` must be [1, m] and `pos` [1, 3]; free dimensions are checked on
/// the first run instead.
pub(crate) fn check_output_dims(
    path: &Path,
    probs: &[Dim],
    pos: &[Dim],
    expect: ModelShape,
) -> Result<(), InferenceError> {
    let mismatch = |expected: String, found: &[Dim]| InferenceError::OutputMismatch {
        path: path.to_path_buf(),
        expected,
        found: format_dims(found),
    };
    if probs.len() != 2 || !fits(probs[0], 1) {
        return Err(mismatch(format!("`{PROBS_NAME}` of shape [1, m]"), probs));
    }
    if let Some(found) = probs[1]
        && !fits(Some(found), expect.classes)
    {
        return Err(InferenceError::ClassCountMismatch {
            path: path.to_path_buf(),
            expected: expect.classes,
            found: usize::try_from(found).unwrap_or(0),
        });
    }
    if pos.len() != 2 || !fits(pos[0], 1) || !fits(pos[1], 3) {
        return Err(mismatch(format!("`{POS_NAME}` of shape [1, 3]"), pos));
    }
    Ok(())
}

/// Checks the raw output buffers of one run and packs them.
pub(crate) fn output_from_slices(
    path: &Path,
    probs: &[f32],
    pos: &[f32],
    expect: ModelShape,
) -> Result<NetOutput, InferenceError> {
    if probs.len() != expect.classes {
        return Err(InferenceError::ClassCountMismatch {
            path: path.to_path_buf(),
            expected: expect.classes,
            found: probs.len(),
        });
    }
    let pos_offset_m: [f32; 3] = pos.try_into().map_err(|_| InferenceError::OutputMismatch {
        path: path.to_path_buf(),
        expected: format!("`{POS_NAME}` with 3 values"),
        found: format!("{} values", pos.len()),
    })?;
    if !probs.iter().all(|p| p.is_finite()) {
        return Err(InferenceError::NonFiniteOutput {
            path: path.to_path_buf(),
            output: PROBS_NAME,
        });
    }
    if !pos_offset_m.iter().all(|p| p.is_finite()) {
        return Err(InferenceError::NonFiniteOutput {
            path: path.to_path_buf(),
            output: POS_NAME,
        });
    }
    Ok(NetOutput {
        probs: probs.to_vec(),
        pos_offset_m,
    })
}

/// Load-time check on the output of a zero image: `probs` is a distribution.
pub(crate) fn check_softmax(path: &Path, output: &NetOutput) -> Result<(), InferenceError> {
    let sum: f32 = output.probs.iter().sum();
    let non_negative = output.probs.iter().all(|p| *p >= 0.0);
    if !non_negative || (sum - 1.0).abs() > SOFTMAX_SUM_TOLERANCE {
        return Err(InferenceError::OutputMismatch {
            path: path.to_path_buf(),
            expected: format!("`{PROBS_NAME}` to be a softmax (non-negative, summing to 1)"),
            found: format!("sum {sum}, all non-negative: {non_negative} (is the Softmax missing?)"),
        });
    }
    Ok(())
}

/// Checks the depth image given to `infer`.
pub(crate) fn check_depth(depth: &[f32], expect: ModelShape) -> Result<(), InferenceError> {
    if depth.len() != expect.pixels() {
        return Err(InferenceError::InputLength {
            expected: expect.pixels(),
            found: depth.len(),
            image_size: expect.image_size,
        });
    }
    if let Some((index, value)) = depth.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(InferenceError::NonFiniteInput {
            index,
            value: *value,
        });
    }
    Ok(())
}

#[cfg(test)]
#[path = "contract_tests.rs"]
mod tests;
