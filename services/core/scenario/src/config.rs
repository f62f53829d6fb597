//! Scenario selection and parameters.

use crate::error::ScenarioError;
use crate::look_away::LookAway;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Which relative-motion scenario to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ScenarioKind {
    /// Seed 000 §4.3: target spinning at 1°/s about `y_LVLH`, inspection then
    /// approach from 15 m to 3 m.
    SlowSpin,
    /// Seed 000 §4.4: torque-free axisymmetric target spinning at 10°/s with
    /// nutation, approach from 15 m to 3 m.
    Tumbling,
    /// Seed 002 §4.3: passive safety ellipse (25-53 m) over two orbits, one
    /// frame every 50 s, slowly tumbling target.
    Ellipse,
    /// Seed 002 §4.3: independent frames with uniformly drawn 321 Euler angles
    /// at a fixed range.
    Random,
}

impl ScenarioKind {
    /// Every scenario, in a stable order.
    pub const ALL: [ScenarioKind; 4] = [
        ScenarioKind::SlowSpin,
        ScenarioKind::Tumbling,
        ScenarioKind::Ellipse,
        ScenarioKind::Random,
    ];

    /// The command-line name (`slow-spin`, `tumbling`, `ellipse`, `random`).
    pub fn as_str(&self) -> &'static str {
        match self {
            ScenarioKind::SlowSpin => "slow-spin",
            ScenarioKind::Tumbling => "tumbling",
            ScenarioKind::Ellipse => "ellipse",
            ScenarioKind::Random => "random",
        }
    }
}

impl fmt::Display for ScenarioKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for ScenarioKind {
    type Err = ScenarioError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let wanted = s.trim().to_ascii_lowercase().replace('_', "-");
        ScenarioKind::ALL
            .into_iter()
            .find(|k| k.as_str() == wanted)
            .ok_or_else(|| ScenarioError::UnknownKind(s.to_string()))
    }
}

/// Parameters of a scenario. Build one with [`ScenarioConfig::default_for`]
/// and override fields as needed; [`crate::build`] validates it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScenarioConfig {
    /// Which scenario.
    pub kind: ScenarioKind,
    /// Seed of every random draw (initial spin phase, pointing error, random
    /// attitudes).
    pub seed: u64,
    /// Time between two frames (s): 1 s for the seed 000 runs, 50 s for the
    /// safety ellipse. The first frame ends at `t = frame_period_s`.
    pub frame_period_s: f64,
    /// `>= 1`: the chaser trajectory (and, for the ellipse, the orbit) runs
    /// this many times faster; the target's own rotation keeps its true rate.
    /// Ignored by the random scenario (its frames are independent).
    pub compression: f64,
    /// Range of the target centre of mass (m), random scenario only.
    pub range_m: f64,
    /// Slow-spin and tumbling: every range of the chaser's legs (seed 000
    /// §4.3-4.4: 15 m fly-around down to 3 m, set for a 1.6 m-radius
    /// mockup) multiplied by this factor (>= 1), so that a larger target
    /// is seen whole at the fly-around. Default 1 (the paper's legs).
    #[serde(default = "unit_range_scale")]
    pub range_scale: f64,
    /// Amplitude (deg, per sensor axis) of the smooth pointing error of the
    /// boresight, so the target is not always dead centre. Default 0.3°.
    pub pointing_error_deg: f64,
    /// Random scenario: the centre of mass is offset from the boresight by an
    /// angle drawn uniformly in `[-lateral_offset_deg, lateral_offset_deg]`
    /// about each of sensor x and y. Default 1° (±0.35 m at 20 m).
    pub lateral_offset_deg: f64,
    /// Random scenario: number of independent frames (seed 002: 500 per range).
    pub random_frames: usize,
    /// Frames during which the sensor looks away from the target (the
    /// loss-and-reacquisition variant); `None` (default) = never.
    #[serde(default)]
    pub look_away: Option<LookAway>,
}

fn unit_range_scale() -> f64 {
    1.0
}

impl Default for ScenarioConfig {
    fn default() -> Self {
        Self::default_for(ScenarioKind::SlowSpin)
    }
}

impl ScenarioConfig {
    /// The paper's settings for a scenario: 1 Hz frames (50 s for the
    /// ellipse), no compression, seed 0, 20 m range, 0.3° pointing error,
    /// 1° lateral offset and 500 random frames.
    pub fn default_for(kind: ScenarioKind) -> Self {
        let frame_period_s = match kind {
            ScenarioKind::Ellipse => 50.0,
            _ => 1.0,
        };
        Self {
            kind,
            seed: 0,
            frame_period_s,
            compression: 1.0,
            range_m: 20.0,
            range_scale: 1.0,
            pointing_error_deg: 0.3,
            lateral_offset_deg: 1.0,
            random_frames: 500,
            look_away: None,
        }
    }

    /// Rejects NaN/non-positive periods and ranges, compression below 1,
    /// out-of-bounds error amplitudes and an invalid look-away window.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        if !(self.frame_period_s.is_finite() && self.frame_period_s > 0.0) {
            return Err(ScenarioError::InvalidFramePeriod(self.frame_period_s));
        }
        if !(self.compression.is_finite() && self.compression >= 1.0) {
            return Err(ScenarioError::InvalidCompression(self.compression));
        }
        if !(self.range_m.is_finite() && self.range_m > 0.0) {
            return Err(ScenarioError::InvalidRange(self.range_m));
        }
        if !(self.range_scale.is_finite() && self.range_scale >= 1.0) {
            return Err(ScenarioError::InvalidRangeScale(self.range_scale));
        }
        if !(self.pointing_error_deg.is_finite() && (0.0..=5.0).contains(&self.pointing_error_deg))
        {
            return Err(ScenarioError::InvalidPointingError(self.pointing_error_deg));
        }
        if !(self.lateral_offset_deg.is_finite() && (0.0..=10.0).contains(&self.lateral_offset_deg))
        {
            return Err(ScenarioError::InvalidLateralOffset(self.lateral_offset_deg));
        }
        if self.kind == ScenarioKind::Random && self.random_frames == 0 {
            return Err(ScenarioError::NoFrames);
        }
        if let Some(look) = &self.look_away {
            look.validate()?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kind_parses_and_prints_round_trip() {
        for kind in ScenarioKind::ALL {
            assert_eq!(kind.to_string().parse::<ScenarioKind>().unwrap(), kind);
        }
        assert_eq!(
            "Slow_Spin".parse::<ScenarioKind>().unwrap(),
            ScenarioKind::SlowSpin
        );
        assert!(matches!(
            "spin".parse::<ScenarioKind>(),
            Err(ScenarioError::UnknownKind(_))
        ));
    }

    #[test]
    fn defaults_are_valid_and_bad_values_are_errors() {
        for kind in ScenarioKind::ALL {
            ScenarioConfig::default_for(kind).validate().unwrap();
        }
        let base = ScenarioConfig::default_for(ScenarioKind::Random);
        let bad = [
            ScenarioConfig {
                frame_period_s: f64::NAN,
                ..base.clone()
            },
            ScenarioConfig {
                frame_period_s: 0.0,
                ..base.clone()
            },
            ScenarioConfig {
                frame_period_s: -1.0,
                ..base.clone()
            },
            ScenarioConfig {
                compression: 0.5,
                ..base.clone()
            },
            ScenarioConfig {
                compression: f64::NAN,
                ..base.clone()
            },
            ScenarioConfig {
                range_m: f64::NAN,
                ..base.clone()
            },
            ScenarioConfig {
                range_m: 0.0,
                ..base.clone()
            },
            ScenarioConfig {
                pointing_error_deg: -0.1,
                ..base.clone()
            },
            ScenarioConfig {
                lateral_offset_deg: f64::INFINITY,
                ..base.clone()
            },
            ScenarioConfig {
                random_frames: 0,
                ..base.clone()
            },
        ];
        for cfg in bad {
            assert!(cfg.validate().is_err(), "{cfg:?} should be rejected");
        }
    }

    #[test]
    fn config_serialises_with_kebab_case_kind() {
        let cfg = ScenarioConfig::default_for(ScenarioKind::SlowSpin);
        let text = serde_json::to_string(&cfg).unwrap();
        assert!(text.contains("\"slow-spin\""));
        let back: ScenarioConfig = serde_json::from_str(&text).unwrap();
        assert_eq!(back, cfg);
    }
}
