//! `spacepose eval tm`: seed 002 on-line template matching with ICP
//! refinement on simulated frames, scored against truth (§4.2-4.5,
//! Fig. 8, Tables 2 and 4).
//!
//! Conditions: the raster sensor of seed 002 §4.1 (40°×40° at 1°,
//! [`SensorConfig::raster_seed002`]) with every effect on but facility
//! clutter (noise, line-of-sight error, outliers, detection losses, beam
//! divergence, reflections, motion blur). A solution is a success when the
//! attitude error after ICP is below 3° (§4.2), with d_sym (seed 004
//! Eq. 14) for targets with symmetries. `--sensor-effects seed002` keeps
//! only the effects seed 002 §3.2 simulates (detection, range and
//! line-of-sight noise, 4σ range outliers), to tell what the extra effects
//! cost. Acquisitions run one after the
//! other, so the time is that of one acquisition with the requested
//! threads; frames are simulated beforehand, in parallel.

use crate::stats::MeanMax;
mod render;

use crate::common::load_target;
use crate::common::progress_bar;
use anyhow::{Context, Result, bail};
use clap::Args;
use nalgebra::{Rotation3, UnitQuaternion};
use rayon::prelude::*;
use serde::Serialize;
use spacepose_acquisition::{
    AcquisitionOutcome, CoarseToFine, FarLevel, FarLookup, TemplateMatcher, TemplateMatchingConfig,
    Threads,
};
use spacepose_geometry::{Euler321, so3};
use spacepose_lidar_sim::{Effects, Frame, LidarSimulator, SensorConfig};
use spacepose_scenario::ScenarioKind;
use spacepose_scenario::{ScenarioConfig, build};
use std::path::PathBuf;

/// Success threshold on the attitude error after ICP (seed 002 §4.2).
pub const SUCCESS_DEG: f64 = 3.0;

/// Options shared by `eval tm` and `calibrate fconv`.
#[derive(Debug, Clone, Args)]
pub struct TmOptions {
    /// Built-in target or mesh file.
    #[arg(long, default_value = "envisat")]
    pub target: String,
    /// Scale applied to a mesh file's coordinates.
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// Range of the random scenario (m).
    #[arg(long, default_value_t = 20.0)]
    pub range: f64,
    /// Euler-angle sampling step Δ (deg).
    #[arg(long, default_value_t = 30.0)]
    pub delta: f64,
    /// The fast variant (D_BOR test, Eq. 3).
    #[arg(long)]
    pub fast: bool,
    /// τ of Eq. (3).
    #[arg(long, default_value_t = 0.1)]
    pub tau: f64,
    /// Frames to acquire (default: 50 for random, the whole ellipse).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub count: Option<u64>,
    /// Seed of the scenario and the sensor.
    #[arg(long, default_value_t = 7)]
    pub seed: u64,
    /// 1: single-threaded template matching (fair timing); otherwise all cores.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Sensor effects of the simulated frames.
    #[arg(long, value_enum, default_value_t = SensorEffects::All)]
    pub sensor_effects: SensorEffects,
    /// Position from the trimmed centroid (seed 004) instead of the mean.
    #[arg(long)]
    pub trimmed: bool,
    /// Candidates refined fully by ICP, lowest f_CONV kept (1 with
    /// `--screen-candidates 0` = seed 002). Default: the library's (2).
    #[arg(long)]
    pub icp_candidates: Option<usize>,
    /// Distinct templates screened by a short ICP before the refinement
    /// (0 = off). Default: the library's (100).
    #[arg(long)]
    pub screen_candidates: Option<usize>,
    /// Screening work budget in cloud points (candidates ≤ budget /
    /// points; 0 = no budget). Default: the library's (9000).
    #[arg(long)]
    pub screen_budget: Option<usize>,
    /// Cloud points each screening ICP uses (0 = all). Default: the
    /// library's.
    #[arg(long)]
    pub screen_max_points: Option<usize>,
    /// Screened poses re-ranked by the unexplained fraction before the
    /// refinement (0 = by the screening score alone). Default: the
    /// library's (8).
    #[arg(long)]
    pub screen_rerank: Option<usize>,
    /// Bin edge (m) of the translation vote placing each candidate (0 =
    /// off, centroid alignment only). Default: the library's (1).
    #[arg(long)]
    pub vote_bin: Option<f64>,
    /// No second chance (translation vote and refinement again) for a
    /// rejected solution.
    #[arg(long)]
    pub no_revote: bool,
    /// The second chance does not try the rejected attitude turned 180°
    /// about each body axis.
    #[arg(long)]
    pub no_revote_flips: bool,
    /// Per-point cap (m) of f_CONV (0 = seed 002's uncapped mean).
    /// Default: the library's.
    #[arg(long)]
    pub f_conv_cap: Option<f64>,
    /// Reach (m) of the second chance's slide search along the sensed
    /// cloud's principal axis (0 = off). Default: the library's.
    #[arg(long)]
    pub slide_reach: Option<f64>,
    /// Re-renderings of each candidate at its aligned origin before its
    /// ICP (0 = seed 002's centroid alignment only). Default: the
    /// library's.
    #[arg(long)]
    pub recentre_iterations: Option<usize>,
    /// Weight (m²) of the unexplained fraction when the refined
    /// candidates are compared (0 = by f_CONV alone). Default: the
    /// library's.
    #[arg(long)]
    pub unexplained_weight: Option<f64>,
    /// Acceptance bound on the unexplained fraction (1 = off). Default:
    /// the library's.
    #[arg(long)]
    pub u_max: Option<f64>,
    /// Ray thinning of every template (1 = every sensor ray).
    #[arg(long, default_value_t = 1)]
    pub template_stride: usize,
    /// Coarse-to-fine: first pass with this ray thinning (0 = off, every
    /// template at full resolution as in seed 002)...
    #[arg(long, default_value_t = 3)]
    pub coarse_stride: usize,
    /// ...then the best N templates at full resolution.
    #[arg(long, default_value_t = 30)]
    pub coarse_keep: usize,
    /// Sensor points in the correlation (0 = all). Default: the
    /// library's.
    #[arg(long)]
    pub max_corr_points: Option<usize>,
    /// f_MAX (m²) for the accepted flag.
    #[arg(long)]
    pub f_max: Option<f64>,
    /// Truncated f_CONV (squared distances capped at the final ICP's
    /// correspondence distance²) instead of seed 002 §4.5's plain mean.
    #[arg(long)]
    pub robust_f_conv: bool,
    /// The wide stages' approximate nearest-point lookup: `off`, or its
    /// grids as `EDGE:MARGIN,...` in metres, finest first (default: the
    /// library's, `0.05:0.6,0.2:6`).
    #[arg(long)]
    pub far_levels: Option<String>,
    /// Narrowest stage distance (m) that uses the approximate lookup.
    /// Default: the library's.
    #[arg(long)]
    pub far_from: Option<f64>,
}

/// `spacepose eval tm`.
#[derive(Debug, Args)]
pub struct EvalTmArgs {
    /// Scenario: random (fixed range) or ellipse (seed 002 §4.3).
    #[arg(long, default_value = "random")]
    pub scenario: ScenarioKind,
    /// Matching options.
    #[command(flatten)]
    pub options: TmOptions,
    /// Write the report as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Also list every frame.
    #[arg(long)]
    pub frames: bool,
}

impl TmOptions {
    /// The library configuration.
    ///
    /// Errors: a malformed `--far-levels`.
    pub fn matching(&self) -> Result<TemplateMatchingConfig> {
        let d = TemplateMatchingConfig::default();
        Ok(TemplateMatchingConfig {
            delta_deg: self.delta,
            fast: self.fast,
            tau: self.tau,
            trimmed_centroid: self.trimmed,
            threads: if self.threads == 1 {
                Threads::Single
            } else {
                Threads::All
            },
            f_max_m2: self.f_max.unwrap_or(d.f_max_m2),
            icp_candidates: self.icp_candidates.unwrap_or(d.icp_candidates),
            screen_candidates: self.screen_candidates.unwrap_or(d.screen_candidates),
            screen_point_budget: self.screen_budget.unwrap_or(d.screen_point_budget),
            screen_max_points: self.screen_max_points.unwrap_or(d.screen_max_points),
            screen_rerank: self.screen_rerank.unwrap_or(d.screen_rerank),
            translation_vote_bin_m: self.vote_bin.unwrap_or(d.translation_vote_bin_m),
            revote: d.revote && !self.no_revote,
            revote_flips: d.revote_flips && !self.no_revote_flips,
            slide_reach_m: self.slide_reach.unwrap_or(d.slide_reach_m),
            recentre_iterations: self.recentre_iterations.unwrap_or(d.recentre_iterations),
            unexplained_weight_m2: self.unexplained_weight.unwrap_or(d.unexplained_weight_m2),
            u_max: self.u_max.unwrap_or(d.u_max),
            template_stride: self.template_stride,
            coarse_to_fine: (self.coarse_stride > 0).then_some(CoarseToFine {
                stride: self.coarse_stride,
                keep: self.coarse_keep,
            }),
            max_correlation_points: self.max_corr_points.unwrap_or(d.max_correlation_points),
            robust_f_conv: self.robust_f_conv,
            f_conv_cap_m: self.f_conv_cap.unwrap_or(d.f_conv_cap_m),
            far_lookup: self.far_lookup()?,
            ..d
        })
    }

    /// The far lookup: the library's, with the flags' changes.
    fn far_lookup(&self) -> Result<Option<FarLookup>> {
        let mut far = FarLookup::default();
        if let Some(spec) = &self.far_levels {
            if spec == "off" {
                return Ok(None);
            }
            far.levels = spec
                .split(',')
                .map(|level| {
                    let (edge, margin) = level
                        .split_once(':')
                        .with_context(|| format!("far level {level:?}: expected EDGE:MARGIN"))?;
                    Ok(FarLevel {
                        resolution_m: edge.trim().parse().context("far level edge")?,
                        margin_m: margin.trim().parse().context("far level margin")?,
                    })
                })
                .collect::<Result<_>>()?;
        }
        if let Some(from) = self.far_from {
            far.from_m = from;
        }
        Ok(Some(far))
    }
}

/// One acquisition, scored.
#[derive(Debug, Clone, Serialize)]
pub struct TmFrame {
    /// Frame index.
    pub frame: usize,
    /// True range of the centre of mass (m).
    pub range_m: f64,
    /// Points in the frame.
    pub points: usize,
    /// Attitude error after ICP (deg, d_sym); NaN without a pose.
    pub err_deg: f64,
    /// Position error after ICP (m).
    pub err_m: f64,
    /// Attitude error of the template solution (deg, d_sym).
    pub coarse_err_deg: f64,
    /// |Δ| of yaw, pitch, roll of the template solution (deg).
    pub coarse_euler_err_deg: [f64; 3],
    /// err_deg < 3°.
    pub success: bool,
    /// f_CONV (m²), infinite when no refinement.
    pub f_conv_m2: f64,
    /// Unexplained fraction of the solution (see
    /// `spacepose_acquisition::visibility`), 1 when no refinement.
    pub unexplained_fraction: f64,
    /// The acquisition accepted the solution (f_CONV ≤ f_MAX and
    /// unexplained fraction ≤ U_MAX).
    pub accepted: bool,
    /// Acquisition time (ms).
    pub time_ms: f64,
    /// Of which template matching (ms).
    pub matching_ms: f64,
    /// Of which ICP (ms).
    pub refinement_ms: f64,
    /// Templates rendered.
    pub templates_generated: usize,
    /// Templates correlated.
    pub templates_evaluated: usize,
    /// The acquisition error, if any (counted as a failure).
    pub error: Option<String>,
    /// The solution, target body → sensor: `[x, y, z, qw, qx, qy, qz]`
    /// (m; unit quaternion); `None` without one. For diagnostics against
    /// the frames `spacepose sim` writes for the same scenario and seed.
    pub t_sensor_target: Option<[f64; 7]>,
}

/// Means of the template counts.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct TemplateCounts {
    /// Templates rendered per acquisition.
    pub generated: f64,
    /// Templates correlated per acquisition.
    pub evaluated: f64,
    /// Grid size.
    pub grid: usize,
}

/// Summary of an `eval tm` run.
#[derive(Debug, Clone, Serialize)]
pub struct TmReport {
    /// Target name.
    pub target: String,
    /// Scenario name.
    pub scenario: String,
    /// Range (random scenario) or NaN.
    pub range_m: f64,
    /// Seed.
    pub seed: u64,
    /// Sensor effects of the frames.
    pub sensor_effects: SensorEffects,
    /// Frames.
    pub count: usize,
    /// Matching configuration.
    pub config: TemplateMatchingConfig,
    /// Successes over frames.
    pub success_rate: f64,
    /// Accepted (f_CONV ≤ f_MAX and unexplained fraction ≤ U_MAX) over
    /// frames.
    pub accepted_rate: f64,
    /// Accepted successes over frames: how often a frame gives tracking a
    /// correct pose it may use.
    pub accepted_success_rate: f64,
    /// Accepted failures.
    pub false_accepts: usize,
    /// Rejected successes.
    pub false_rejects: usize,
    /// Acquisition time (ms).
    pub time_ms: MeanMax,
    /// Template-matching part (ms).
    pub matching_ms: MeanMax,
    /// ICP part (ms).
    pub refinement_ms: MeanMax,
    /// Template counts.
    pub templates: TemplateCounts,
    /// Mean |Δ yaw|, |Δ pitch|, |Δ roll| of the template solution over the
    /// successes (deg, seed 002 Table 2).
    pub euler_err_deg: [f64; 3],
    /// Mean attitude error after ICP over the successes (deg).
    pub err_deg_success_mean: f64,
    /// f_CONV over the successes (m², Table 4).
    pub fconv_success_max: f64,
    /// Mean f_CONV over the successes.
    pub fconv_success_mean: f64,
    /// f_CONV over the failures (m², Table 4).
    pub fconv_failure_min: f64,
    /// Mean f_CONV over the failures.
    pub fconv_failure_mean: f64,
    /// `fconv_success_max < fconv_failure_min`.
    pub separable: bool,
    /// Unexplained fraction over the successes (max).
    pub unexplained_success_max: f64,
    /// Unexplained fraction over the failures that f_CONV alone would
    /// accept (min; NaN without such failures).
    pub unexplained_failure_min: f64,
    /// Mean points per frame.
    pub mean_points: f64,
    /// Every frame.
    pub frames: Vec<TmFrame>,
}

/// Which sensor effects the frames of `eval tm` carry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SensorEffects {
    /// Every effect but facility clutter (the reported figures).
    All,
    /// Seed 002 §3.2's effects only: detection (Eq. 4), range and
    /// line-of-sight noise, outliers at 4 σ_RANGE; no beam divergence
    /// (mixed returns), no reflections, no motion blur.
    Seed002,
}

impl SensorEffects {
    fn effects(self) -> Effects {
        match self {
            SensorEffects::All => Effects::default(),
            SensorEffects::Seed002 => Effects {
                beam_divergence: false,
                reflections: false,
                motion_blur: false,
                clutter: false,
                ..Effects::all()
            },
        }
    }
}

/// Runs the acquisitions of `scenario` and scores them.
pub fn evaluate(scenario_arg: ScenarioKind, options: &TmOptions) -> Result<TmReport> {
    if !matches!(scenario_arg, ScenarioKind::Random | ScenarioKind::Ellipse) {
        bail!("template matching is evaluated on random or ellipse (seed 002 §4.3)");
    }
    let target = load_target(&options.target, options.scale)?;
    let sensor = SensorConfig::raster_seed002();
    let matching = options.matching()?;
    let matcher = TemplateMatcher::new(target.clone(), sensor.clone(), matching.clone())
        .context("building the template matcher")?;
    let mut scenario_config = ScenarioConfig::default_for(scenario_arg);
    scenario_config.seed = options.seed;
    scenario_config.range_m = options.range;
    let count = options
        .count
        .map(|c| c as usize)
        .unwrap_or(match scenario_arg {
            ScenarioKind::Random => 50,
            _ => usize::MAX,
        });
    scenario_config.random_frames = count.min(100_000);
    let scenario = build(&scenario_config).context("invalid scenario")?;
    let count = count.min(scenario.natural_frame_count());
    let mut sim_sensor = sensor;
    sim_sensor.effects = options.sensor_effects.effects();
    let simulator = LidarSimulator::new(target.clone(), sim_sensor).context("simulator")?;
    let end_times = scenario.frame_end_times(count);
    let bar = progress_bar(count as u64, "acquiring");
    let mut frames = Vec::with_capacity(count);
    for (b, batch) in end_times.chunks(16).enumerate() {
        let simulated: Vec<Frame> = batch
            .par_iter()
            .enumerate()
            .map(|(i, &t)| {
                let mut rng = LidarSimulator::frame_rng(options.seed, (b * 16 + i) as u64);
                simulator.simulate(&scenario.state_at(t), &mut rng)
            })
            .collect();
        for (i, frame) in simulated.iter().enumerate() {
            let result = matcher.acquire(&frame.points);
            frames.push(score(b * 16 + i, frame, result, target.symmetries()));
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    Ok(summarise(
        target.name(),
        scenario.name(),
        options,
        matching,
        matcher.grid_len(),
        frames,
    ))
}

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

fn score(
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

fn summarise(
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

/// The report as text: the header line, the summary table and, with
/// `with_frames`, the per-frame table.
pub fn render(report: &TmReport, with_frames: bool) -> String {
    let mut out = render::header(report);
    out.push_str(&render::summary_table(report).render());
    if with_frames {
        out.push('\n');
        out.push_str(&render::frames_table(&report.frames).render());
    }
    out
}

/// `spacepose eval tm`.
pub fn run(args: &EvalTmArgs) -> Result<()> {
    let report = evaluate(args.scenario, &args.options)?;
    println!("{}", render(&report, args.frames));
    if let Some(path) = &args.json {
        let json = serde_json::to_string_pretty(&report)?;
        std::fs::write(path, json).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::SensorEffects;

    #[test]
    fn seed002_effects_are_the_papers_list() {
        let e = SensorEffects::Seed002.effects();
        assert!(e.range_noise && e.los_noise && e.outliers && e.detection);
        assert!(!e.beam_divergence && !e.reflections && !e.motion_blur && !e.clutter);
        let all = SensorEffects::All.effects();
        assert!(all.beam_divergence && all.reflections && all.motion_blur && !all.clutter);
    }
}
