//! Scoring of each held-out frame against its truth: the network's pose and
//! the refined one, with d_sym (seed 004 Eq. 14) and the thresholds of §V.A.

use super::report::CnnFrame;
use spacepose_cnn::{CnnEstimator, GeneratedFrame};
use spacepose_geometry::{Pose, so3};

/// Success thresholds of seed 004 §V.A.
pub const SUCCESS_DEG: f64 = 5.0;
/// Position threshold (cm).
pub const SUCCESS_CM: f64 = 15.0;

/// Errors of `estimate` against the truth: (deg with d_sym, cm).
fn errors(estimate: &Pose, truth: &Pose, syms: &[nalgebra::Rotation3<f64>]) -> (f64, f64) {
    let deg = so3::distance_sym(&estimate.rotation, &truth.rotation, syms).to_degrees();
    let cm = (estimate.translation - truth.translation).norm() * 100.0;
    (deg, cm)
}

/// Time spanned by the points' timestamps (s).
fn scan_duration(points: &[spacepose_geometry::Point]) -> f64 {
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.t), hi.max(p.t))
        });
    if hi >= lo { hi - lo } else { 0.0 }
}

/// The record of held-out frame `index`, estimated and scored.
pub fn score(estimator: &CnnEstimator, index: u64, f: &GeneratedFrame) -> CnnFrame {
    let truth = &f.truth.t_sensor_target;
    let syms = estimator.classes().symmetries();
    let mut row = CnnFrame {
        frame: index,
        range_m: truth.translation.norm(),
        points: f.points.len(),
        rate_deg_s: f.truth.w_target.norm().to_degrees(),
        scan_s: scan_duration(&f.points),
        raw_err_deg: f64::NAN,
        raw_err_cm: f64::NAN,
        err_deg: f64::NAN,
        err_cm: f64::NAN,
        success_raw: false,
        success_refined: false,
        f_conv_m2: f64::INFINITY,
        accepted: false,
        twins: spacepose_cnn::TwinOutcome::default(),
        top_probability: 0.0,
        hypothesis: 0,
        hypotheses_refined: 0,
        time_ms: spacepose_cnn::Timings::default(),
        fconv_ms: f64::NAN,
        error: None,
    };
    match estimator.estimate(&f.points) {
        Ok(e) => {
            (row.raw_err_deg, row.raw_err_cm) = errors(&e.t_sensor_target_raw, truth, syms);
            row.success_raw = row.raw_err_deg < SUCCESS_DEG && row.raw_err_cm < SUCCESS_CM;
            if e.refinement_error.is_none() {
                (row.err_deg, row.err_cm) = errors(&e.t_sensor_target, truth, syms);
                row.success_refined = row.err_deg < SUCCESS_DEG && row.err_cm < SUCCESS_CM;
            }
            row.f_conv_m2 = e.f_conv_m2;
            row.accepted = e.accepted;
            row.twins = e.twins;
            row.top_probability = e.top_probability;
            row.hypothesis = e.hypothesis;
            row.hypotheses_refined = e.hypotheses_refined;
            row.time_ms = e.time_ms;
            row.fconv_ms = e.fconv_ms;
            row.error = e.refinement_error;
        }
        Err(e) => row.error = Some(e.to_string()),
    }
    row
}
