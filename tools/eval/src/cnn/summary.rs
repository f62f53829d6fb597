//! The summary of a scored held-out set: success rates, errors over the
//! successes, the time split, the f_CONV check and success by range.

use super::args::EvalCnnArgs;
use super::report::{
    CnnFrame, CnnReport, FconvStats, MeanStd, RangeBin, RawRefined, TimeSplit, TimeStats,
};
use crate::stats::median;
use spacepose_cnn::{CnnEstimator, EstimatorConfig};

/// The summary of the scored `frames`.
pub fn report(
    args: &EvalCnnArgs,
    estimator: &CnnEstimator,
    model: &std::path::Path,
    config: EstimatorConfig,
    frames: Vec<CnnFrame>,
) -> CnnReport {
    let n = frames.len().max(1) as f64;
    CnnReport {
        target: args.target.clone(),
        model: model.display().to_string(),
        engine: estimator.engine().to_string(),
        seed: args.seed,
        mismatch: args.mismatch,
        count: frames.len(),
        success_rate_refined: rate(&frames, |r| r.success_refined),
        success_rate_raw: rate(&frames, |r| r.success_raw),
        accepted_correct_rate: rate(&frames, accepted_correct),
        false_accept_rate: rate(&frames, false_accept),
        ang_err_deg: raw_refined(&frames, |r| r.raw_err_deg, |r| r.err_deg),
        pos_err_cm: raw_refined(&frames, |r| r.raw_err_cm, |r| r.err_cm),
        time_ms: time_split(&frames),
        fconv: fconv_stats(&frames, estimator.f_max_m2()),
        by_range: range_bins(&frames),
        errors: count(&frames, |r| r.error.is_some()),
        other_hypothesis: count(&frames, |r| r.hypothesis > 0),
        several_hypotheses: count(&frames, |r| r.hypotheses_refined > 1),
        twins_refined: count(&frames, |r| r.twins.twins_refined > 0),
        twin_used: count(&frames, |r| r.twins.twin.is_some()),
        // An empty f64 sum is -0.0, which prints as "-0".
        mean_points: if frames.is_empty() {
            0.0
        } else {
            frames.iter().map(|r| r.points as f64).sum::<f64>() / n
        },
        config,
        frames,
    }
}

/// Accepted by the f_CONV check and a refined success.
fn accepted_correct(r: &CnnFrame) -> bool {
    r.accepted && r.success_refined
}

/// Accepted by the f_CONV check and not a refined success.
fn false_accept(r: &CnnFrame) -> bool {
    r.accepted && !r.success_refined
}

/// Frames for which `keep` holds.
fn count(frames: &[CnnFrame], keep: impl Fn(&CnnFrame) -> bool) -> usize {
    frames.iter().filter(|r| keep(r)).count()
}

/// Frames for which `keep` holds over all frames (over 1 when none).
fn rate(frames: &[CnnFrame], keep: impl Fn(&CnnFrame) -> bool) -> f64 {
    count(frames, keep) as f64 / frames.len().max(1) as f64
}

/// Mean ± std of `value` over the frames for which `keep` holds.
fn mean_std_over(
    frames: &[CnnFrame],
    keep: impl Fn(&CnnFrame) -> bool,
    value: impl Fn(&CnnFrame) -> f64,
) -> MeanStd {
    MeanStd::of(
        &frames
            .iter()
            .filter(|r| keep(r))
            .map(value)
            .collect::<Vec<_>>(),
    )
}

/// An error before refinement over the raw successes and after it over
/// the refined successes.
fn raw_refined(
    frames: &[CnnFrame],
    raw: impl Fn(&CnnFrame) -> f64,
    refined: impl Fn(&CnnFrame) -> f64,
) -> RawRefined {
    RawRefined {
        raw: mean_std_over(frames, |r| r.success_raw, raw),
        refined: mean_std_over(frames, |r| r.success_refined, refined),
    }
}

/// Table IV: the time split over the frames without an error.
fn time_split(frames: &[CnnFrame]) -> TimeSplit {
    let ok: Vec<&CnnFrame> = frames.iter().filter(|r| r.error.is_none()).collect();
    let time =
        |f: fn(&CnnFrame) -> f64| TimeStats::of(&ok.iter().map(|r| f(r)).collect::<Vec<_>>());
    TimeSplit {
        preprocess: time(|r| r.time_ms.preprocess),
        inference: time(|r| r.time_ms.inference),
        refinement: time(|r| r.time_ms.refinement),
        total: time(|r| r.time_ms.total),
    }
}

/// The finite f_CONV values of the refined successes (`success`) or
/// failures (`!success`).
fn fconv_values(frames: &[CnnFrame], success: bool) -> Vec<f64> {
    frames
        .iter()
        .filter(|r| r.success_refined == success && r.f_conv_m2.is_finite())
        .map(|r| r.f_conv_m2)
        .collect()
}

/// The acceptance check against the refined successes, with `f_max_m2`.
fn fconv_stats(frames: &[CnnFrame], f_max_m2: f64) -> FconvStats {
    let (s, f) = (fconv_values(frames, true), fconv_values(frames, false));
    FconvStats {
        f_max_m2,
        accepted_rate: rate(frames, |r| r.accepted),
        false_accepts: count(frames, false_accept),
        false_rejects: count(frames, |r| !r.accepted && r.success_refined),
        success_max_m2: s.iter().copied().fold(f64::NAN, f64::max),
        success_median_m2: median(&s),
        failure_min_m2: f.iter().copied().fold(f64::NAN, f64::min),
        failure_median_m2: median(&f),
    }
}

/// Success by range over 2.5-5, 5-10, 10-15 and 15-20 m (the first bin also
/// holds the frames closer than 2.5 m, the last those at 20 m or beyond).
fn range_bins(frames: &[CnnFrame]) -> Vec<RangeBin> {
    [2.5, 5.0, 10.0, 15.0, 20.0]
        .windows(2)
        .map(|w| range_bin(frames, w[0], w[1]))
        .collect()
}

/// Success of the frames in [`lo`, `hi`) (unbounded below when `lo` ≤
/// 2.5 m, above when `hi` ≥ 20 m).
fn range_bin(frames: &[CnnFrame], lo: f64, hi: f64) -> RangeBin {
    let bin: Vec<&CnnFrame> = frames
        .iter()
        .filter(|r| (r.range_m >= lo || lo <= 2.5) && (r.range_m < hi || hi >= 20.0))
        .collect();
    let k = bin.len().max(1) as f64;
    RangeBin {
        range_m: [lo, hi],
        frames: bin.len(),
        success_rate_refined: bin.iter().filter(|r| r.success_refined).count() as f64 / k,
        success_rate_raw: bin.iter().filter(|r| r.success_raw).count() as f64 / k,
        accepted_correct_rate: bin.iter().filter(|r| accepted_correct(r)).count() as f64 / k,
        false_accept_rate: bin.iter().filter(|r| false_accept(r)).count() as f64 / k,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame at `range_m`, refined successfully when `success`.
    fn frame_at(range_m: f64, success: bool) -> CnnFrame {
        CnnFrame {
            frame: 0,
            range_m,
            points: 1000,
            rate_deg_s: 0.0,
            scan_s: 0.1,
            raw_err_deg: 1.0,
            raw_err_cm: 1.0,
            err_deg: 1.0,
            err_cm: 1.0,
            success_raw: success,
            success_refined: success,
            f_conv_m2: 1e-4,
            accepted: true,
            twins: spacepose_cnn::TwinOutcome::default(),
            top_probability: 0.5,
            hypothesis: 0,
            hypotheses_refined: 1,
            time_ms: spacepose_cnn::Timings::default(),
            fconv_ms: 0.0,
            error: None,
        }
    }

    #[test]
    fn every_frame_falls_in_one_range_bin() {
        let ranges = [1.0, 2.5, 4.9, 5.0, 12.0, 19.9, 20.0, 30.0];
        let frames: Vec<CnnFrame> = ranges.iter().map(|&r| frame_at(r, r < 10.0)).collect();
        let bins = range_bins(&frames);
        let counts: Vec<usize> = bins.iter().map(|b| b.frames).collect();
        assert_eq!(counts, [3, 1, 1, 3]);
        assert_eq!(bins.iter().map(|b| b.frames).sum::<usize>(), ranges.len());
        assert_eq!(bins[0].success_rate_refined, 1.0);
        assert_eq!(bins[3].success_rate_refined, 0.0);
        // Every frame is accepted: the successes are accepted and correct,
        // the failures false accepts.
        assert_eq!(
            (bins[0].accepted_correct_rate, bins[0].false_accept_rate),
            (1.0, 0.0)
        );
        assert_eq!(
            (bins[3].accepted_correct_rate, bins[3].false_accept_rate),
            (0.0, 1.0)
        );
    }
}
