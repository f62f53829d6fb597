//! Scoring of each acquisition against the truth (d_sym, the template
//! solution's Euler errors) and the summary of a run.

use super::args::TmOptions;
use super::report::{TemplateCounts, TmFrame, TmReport};
use crate::stats::MeanMax;
use nalgebra::{Rotation3, UnitQuaternion};
use spacepose_acquisition::{AcquisitionOutcome, TemplateMatchingConfig};
use spacepose_geometry::{Euler321, so3};
use spacepose_lidar_sim::Frame;

/// Success threshold on the attitude error after ICP (seed 002 §4.2).
pub const SUCCESS_DEG: f64 = 3.0;

/// The truth rotation (among its symmetric equivalents) closest to `r`.
fn closest_truth(
    r: &Rotation3<f64>,
    truth: &Rotation3<f64>,
    sym: &[Rotation3<f64>],
) -> Rotation3<f64> {
    sym.iter()
        .map(|s| truth * s)
        .min_by(|a, b| so3::distance(r, a).total_cmp(&so3::distance(r, b)))
        .unwrap_or(*truth)
}

fn wrap_deg(a: f64) -> f64 {
    (a + 180.0).rem_euclid(360.0) - 180.0
}

/// The record of acquisition `index` on `frame`, scored against its truth.
pub fn score(
    index: usize,
    frame: &Frame,
    result: Result<AcquisitionOutcome, spacepose_acquisition::AcquisitionError>,
    sym: &[Rotation3<f64>],
) -> TmFrame {
    let truth = frame.truth.t_sensor_target;
    let mut rec = TmFrame {
        frame: index,
        range_m: truth.translation.norm(),
        points: frame.points.len(),
        err_deg: f64::NAN,
        err_m: f64::NAN,
        coarse_err_deg: f64::NAN,
        coarse_euler_err_deg: [f64::NAN; 3],
        success: false,
        f_conv_m2: f64::INFINITY,
        unexplained_fraction: 1.0,
        accepted: false,
        time_ms: f64::NAN,
        matching_ms: f64::NAN,
        refinement_ms: f64::NAN,
        templates_generated: 0,
        templates_evaluated: 0,
        error: None,
        t_sensor_target: None,
    };
    let out = match result {
        Ok(out) => out,
        Err(e) => {
            rec.error = Some(e.to_string());
            return rec;
        }
    };
    let r = out.t_sensor_target.rotation;
    rec.err_deg = so3::distance_sym(&truth.rotation, &r, sym).to_degrees();
    rec.err_m = (out.t_sensor_target.translation - truth.translation).norm();
    let rc = out.t_sensor_target_coarse.rotation;
    rec.coarse_err_deg = so3::distance_sym(&truth.rotation, &rc, sym).to_degrees();
    let t = Euler321::from_rotation(&closest_truth(&rc, &truth.rotation, sym)).to_degrees();
    let e = Euler321::from_rotation(&rc).to_degrees();
    rec.coarse_euler_err_deg = [0, 1, 2].map(|k| wrap_deg(e[k] - t[k]).abs());
    rec.success = rec.err_deg < SUCCESS_DEG;
    rec.f_conv_m2 = out.f_conv_m2;
    rec.unexplained_fraction = out.unexplained_fraction;
    rec.accepted = out.accepted;
    rec.time_ms = out.time_ms;
    rec.matching_ms = out.matching_ms;
    rec.refinement_ms = out.refinement_ms;
    rec.templates_generated = out.templates_generated;
    rec.templates_evaluated = out.templates_evaluated;
    rec.error = out.refinement_error;
    let (p, q) = (
        out.t_sensor_target.translation,
        UnitQuaternion::from_rotation_matrix(&r),
    );
    rec.t_sensor_target = Some([p.x, p.y, p.z, q.w, q.i, q.j, q.k]);
    rec
}

fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    if n == 0 { f64::NAN } else { s / n as f64 }
}

/// The summary of the scored `frames` (grid: templates in the grid).
pub fn summarise(
    target: &str,
    scenario: &str,
    options: &TmOptions,
    config: TemplateMatchingConfig,
    grid: usize,
    frames: Vec<TmFrame>,
) -> TmReport {
    let n = frames.len().max(1) as f64;
    let ok: Vec<&TmFrame> = frames.iter().filter(|f| f.success).collect();
    let ko: Vec<&TmFrame> = frames.iter().filter(|f| !f.success).collect();
    let fold_max = |v: &[&TmFrame]| v.iter().map(|f| f.f_conv_m2).fold(f64::NAN, f64::max);
    let fold_min = |v: &[&TmFrame]| v.iter().map(|f| f.f_conv_m2).fold(f64::NAN, f64::min);
    let times: Vec<f64> = frames.iter().map(|f| f.time_ms).collect();
    let (fs_max, ff_min) = (fold_max(&ok), fold_min(&ko));
    let f_max_m2 = config.f_max_m2;
    TmReport {
        target: target.to_string(),
        scenario: scenario.to_string(),
        range_m: if scenario == "random" {
            options.range
        } else {
            f64::NAN
        },
        seed: options.seed,
        sensor_effects: options.sensor_effects,
        sensor: options.sensor,
        count: frames.len(),
        config,
        success_rate: ok.len() as f64 / n,
        accepted_rate: frames.iter().filter(|f| f.accepted).count() as f64 / n,
        accepted_success_rate: ok.iter().filter(|f| f.accepted).count() as f64 / n,
        false_accepts: ko.iter().filter(|f| f.accepted).count(),
        false_rejects: ok.iter().filter(|f| !f.accepted).count(),
        time_ms: MeanMax::of(&times),
        matching_ms: MeanMax::of(&frames.iter().map(|f| f.matching_ms).collect::<Vec<_>>()),
        refinement_ms: MeanMax::of(&frames.iter().map(|f| f.refinement_ms).collect::<Vec<_>>()),
        templates: TemplateCounts {
            generated: mean(frames.iter().map(|f| f.templates_generated as f64)),
            evaluated: mean(frames.iter().map(|f| f.templates_evaluated as f64)),
            grid,
        },
        euler_err_deg: [0, 1, 2].map(|k| mean(ok.iter().map(|f| f.coarse_euler_err_deg[k]))),
        err_deg_success_mean: mean(ok.iter().map(|f| f.err_deg)),
        fconv_success_max: fs_max,
        fconv_success_mean: mean(ok.iter().map(|f| f.f_conv_m2)),
        fconv_failure_min: ff_min,
        fconv_failure_mean: mean(ko.iter().map(|f| f.f_conv_m2).filter(|v| v.is_finite())),
        separable: ok.is_empty() || ko.is_empty() || fs_max < ff_min,
        unexplained_success_max: ok
            .iter()
            .map(|f| f.unexplained_fraction)
            .fold(f64::NAN, f64::max),
        unexplained_failure_min: ko
            .iter()
            .filter(|f| f.f_conv_m2 <= f_max_m2)
            .map(|f| f.unexplained_fraction)
            .fold(f64::NAN, f64::min),
        mean_points: mean(frames.iter().map(|f| f.points as f64)),
        frames,
    }
}
