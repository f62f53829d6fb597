//! The command line of `spacepose eval tracking`.

use clap::Args;
use spacepose_scenario::ScenarioKind;
use spacepose_tracker::{CtStart, TrackingMode};
use std::path::PathBuf;
use std::str::FromStr;

/// `--mode`: one tracking mode, several separated by commas, or `all` of
/// them, on the same frames.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Modes {
    /// Every mode, in the order of seed 000's tables.
    All,
    /// One mode.
    One(TrackingMode),
    /// Several modes, in the order given.
    Some(Vec<TrackingMode>),
}

impl Modes {
    /// The modes selected.
    pub fn list(&self) -> Vec<TrackingMode> {
        match self {
            Modes::All => TrackingMode::ALL.to_vec(),
            Modes::One(m) => vec![*m],
            Modes::Some(v) => v.clone(),
        }
    }
}

impl FromStr for Modes {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "all" {
            return Ok(Modes::All);
        }
        if s.contains(',') {
            return s
                .split(',')
                .map(|m| m.trim().parse::<TrackingMode>())
                .collect::<Result<Vec<_>, _>>()
                .map(Modes::Some);
        }
        s.parse().map(Modes::One)
    }
}

/// `--init`: how every suite starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum EvalInit {
    /// The sensor's truth acquisition of the first frame (`truth_init`).
    Truth,
    /// The init service's methods on the frames, as deployed (the CNN when
    /// the target has a model, then template matching), reacquiring after
    /// a loss: no truth reaches the suite.
    Acquire,
}

/// `spacepose eval tracking`.
#[derive(Debug, Args)]
pub struct EvalTrackingArgs {
    /// Scenario (slow-spin or tumbling).
    #[arg(long, default_value = "tumbling")]
    pub scenario: ScenarioKind,
    /// Tracking mode, several separated by commas, or all of them, on the
    /// same frames.
    #[arg(long, default_value = "all")]
    pub mode: Modes,
    /// Frames to run; default: the whole scenario at 1 Hz.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub frames: Option<u64>,
    /// Seed of the scenario and the sensor. Seed 1 was used to tune the
    /// tracker: evaluate on any other.
    #[arg(long, default_value_t = 7)]
    pub seed: u64,
    /// Time compression of the chaser trajectory (>= 1).
    #[arg(long, default_value_t = 1.0)]
    pub compression: f64,
    /// Built-in target or mesh file.
    #[arg(long, default_value = "deos")]
    pub target: String,
    /// Scale applied to a mesh file's coordinates.
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// The test facility's background in the frames (floor, back wall,
    /// robot arm: seed 000 §4.1), which ingest must crop.
    #[arg(long)]
    pub clutter: bool,
    /// The sensor's echo separation (m; `inf`: seed 004's average of every
    /// echo of a beam). Default: the sensor's.
    #[arg(long)]
    pub echo_separation_m: Option<f64>,
    /// The sensor's integration time per frame (s). Default: the frame
    /// period (1 s, seed 000's continuous scanning); the suite's sensor
    /// integrates 0.54 s.
    #[arg(long)]
    pub integration_time_s: Option<f64>,
    /// Model mismatch (issue 25 item 3): the frames show the target as
    /// built (MLI relief, appendages missing from the model, 1 % scale
    /// errors, a displaced centre of mass) moving with the scenario's own
    /// motion within each scan plus the chaser's attitude jitter and an
    /// acceleration; the services keep the nominal package
    /// (`spacepose_lidar_sim::Mismatch`'s defaults).
    #[arg(long)]
    pub mismatch: bool,
    /// First frame of the scenario to run (the trackers start on the truth
    /// at that frame's scan start).
    #[arg(long, default_value_t = 0)]
    pub first_frame: usize,
    /// Frames excluded from the "converged" statistics while the filter
    /// learns the angular velocity (seed 000 §5.2).
    #[arg(long, default_value_t = 10)]
    pub warmup: usize,
    /// NDT degeneracy handling: rotations with a smaller lever arm are
    /// held at the prediction (`NdtParams::min_lever_arm_m`, m; 0 = the
    /// paper), in every mode (`ndt` mode has its own default,
    /// `TrackerConfig::ndt_mode_min_lever_arm_m`). Default: the tracker's.
    #[arg(long)]
    pub min_lever_arm_m: Option<f64>,
    /// Point noise (m) of the geometric measurement covariance fed to the
    /// filter (`TrackerConfig::geometric_sigma_m`; 0 = NDT's information).
    /// Default: the tracker's.
    #[arg(long)]
    pub geometric_sigma_m: Option<f64>,
    /// Tracker configuration (TOML, the `[tracker]` table's fields of a
    /// tracker service config, i.e. `TrackerConfig`) to start from instead
    /// of the defaults; the mode is set per evaluated mode and the flags
    /// below override it.
    #[arg(long)]
    pub tracker_config: Option<PathBuf>,
    /// Start pose of the ct-ndt scan: `fixed` (seed 000 Eq. 14) or
    /// `filter-prior`. Default: the tracker's (filter-prior).
    #[arg(long)]
    pub ct_start: Option<CtStart>,
    /// How every suite starts: from the truth, or acquiring with init.
    #[arg(long, value_enum, default_value = "truth")]
    pub init: EvalInit,
    /// Write the results as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Monte-Carlo over the seeds of `--seeds` instead of one run (`--seed`
    /// is then ignored): per-seed figures with the start-up included, and
    /// their mean, p95, max and 95 % confidence interval, as JSON in this
    /// file
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// The seeds of `--report`: `blind` or `development` (the lists of
    /// tools/eval/seeds.toml), or seeds separated by commas
    #[arg(long, default_value = "blind")]
    pub seeds: String,
    /// Draw the errors over time (.png or .svg), like seed 000 Fig. 9/11.
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modes_parse_as_the_tracker_names_them() {
        assert_eq!("all".parse::<Modes>(), Ok(Modes::All));
        assert_eq!(
            "ct-ndt".parse::<Modes>(),
            Ok(Modes::One(TrackingMode::CtNdt))
        );
        assert!("gicp".parse::<Modes>().is_err());
        assert_eq!(
            "deblur, ct-ndt".parse::<Modes>(),
            Ok(Modes::Some(vec![TrackingMode::Deblur, TrackingMode::CtNdt]))
        );
        assert!("deblur,gicp".parse::<Modes>().is_err());
        assert_eq!(Modes::All.list(), TrackingMode::ALL.to_vec());
    }
}
