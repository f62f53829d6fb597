//! The options of `eval tm` and `calibrate fconv` (the matching settings,
//! the scenario and the sensor effects) and the library configuration they make.

use anyhow::{Context, Result};
use clap::Args;
use serde::Serialize;
use spacepose_acquisition::{CoarseToFine, FarLevel, FarLookup, TemplateMatchingConfig, Threads};
use spacepose_lidar_sim::Effects;
use spacepose_scenario::ScenarioKind;
use std::path::PathBuf;

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
    /// The sensor: seed 002's raster, or the suite's Livox Mid-40 with the
    /// init service's 2 cm voxel filter (the path the suite runs).
    #[arg(long, value_enum, default_value_t = TmSensor::Raster)]
    pub sensor: TmSensor,
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
    /// Reject a solution when another hypothesis (e.g. a near-symmetric
    /// twin) scores within this factor of it (0 = off). Default: the
    /// library's.
    #[arg(long)]
    pub twin_ambiguity: Option<f64>,
    /// Point budget of an acquisition: denser frames and their templates
    /// are thinned alike (0 = every point). Default: the library's.
    #[arg(long)]
    pub max_points: Option<usize>,
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
            max_sensed_points: self.max_points.unwrap_or(d.max_sensed_points),
            twin_ambiguity: self.twin_ambiguity.unwrap_or(d.twin_ambiguity),
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

/// `eval tm --sensor`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum TmSensor {
    /// Seed 002 §4.1's raster (40° × 40° at 1°).
    Raster,
    /// The Livox Mid-40 rosette (0.54 s, ~54,000 rays), frames
    /// voxel-filtered at 2 cm as the init service does (`leaf_size_m`).
    Mid40,
}

impl TmSensor {
    /// The sensor model.
    pub fn config(self) -> spacepose_lidar_sim::SensorConfig {
        match self {
            TmSensor::Raster => spacepose_lidar_sim::SensorConfig::raster_seed002(),
            TmSensor::Mid40 => spacepose_lidar_sim::SensorConfig::livox_mid40(),
        }
    }

    /// The voxel leaf applied before matching (m): the init service's
    /// default for the Mid-40, none for the raster (seed 002).
    pub fn voxel_leaf_m(self) -> Option<f64> {
        match self {
            TmSensor::Raster => None,
            TmSensor::Mid40 => Some(0.02),
        }
    }
}

impl SensorEffects {
    /// The simulator's effects for these frames.
    pub(crate) fn effects(self) -> Effects {
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
