//! The service's configuration file (keys in `deploy/examples/lidar-sim.toml`)
//! and the frames it describes.

use anyhow::Context;
use serde::Deserialize;
use spacepose_lidar_sim::{FrameSource, Mismatch, SensorConfig};
use spacepose_runtime::ServiceConfig;
use spacepose_scenario::{LookAway, ScenarioConfig, ScenarioKind};
use std::path::PathBuf;
use std::sync::Arc;

/// `spacepose-lidar-sim --config FILE`: the simulator's settings.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LidarSimConfig {
    /// Built-in target name or mesh file path.
    pub target: String,
    /// Scale of the target coordinates.
    pub scale: f64,
    /// Relative-motion scenario.
    pub scenario: ScenarioKind,
    /// Seed of the scenario and of every frame's random stream.
    pub seed: u64,
    /// Time compression of the chaser trajectory (>= 1).
    pub compression: f64,
    /// Range of the random scenario (m).
    pub range_m: f64,
    /// Slow-spin and tumbling: every range of the chaser's legs times this
    /// (>= 1; 1 = seed 000's 15 m fly-around down to 3 m). `spacepose demo
    /// --target` sets it so that the target is seen whole at the
    /// fly-around (`spacepose_scenario::presets::range_scale_to_fit`).
    pub range_scale: f64,
    /// Frames to publish; 0 = endless (the scenario restarts after its
    /// natural length, the sensor clock keeps running).
    pub frames: u64,
    /// Integration time of one frame (s).
    pub integration_time_s: f64,
    /// Frames per second; 0 = as fast as the simulator goes.
    pub rate_hz: f64,
    /// Test-facility background (floor, back wall, robot arm).
    pub clutter: bool,
    /// Echoes of one beam farther apart than this (m) are separate returns
    /// and the strongest is reported; `inf` averages them all, as seed 004
    /// does (`SensorConfig::echo_separation_m`).
    pub echo_separation_m: f64,
    /// The world departs from the estimators' model (the `[mismatch]`
    /// table, `spacepose_lidar_sim::Mismatch`): the target as built, and
    /// the scenario's own motion with the chaser's jitter and acceleration
    /// within each scan. Absent: the model's mesh moving with constant
    /// velocities over the scan.
    pub mismatch: Option<Mismatch>,
    /// Publish an acquisition result from the truth for the first frame.
    pub truth_init: bool,
    /// After the last frame (frames > 0): exit, or stay up sending heartbeats.
    pub exit_at_end: bool,
    /// Sensor id written in the cloud headers.
    pub sensor_id: u16,
    /// Frames during which the sensor looks away from the target (e.g.
    /// `look_away = { first_frame = 8, frames = 4, angle_deg = 60.0 }`): the
    /// loss-and-reacquisition variant. Absent = never.
    pub look_away: Option<LookAway>,
    /// File recording the last frame slot taken (written before each
    /// frame); a restarted sensor resumes from it at the frame now due.
    /// `spacepose up` sets `{run dir}/{instance}.sensorstate`. None: every
    /// start begins at frame 0.
    pub checkpoint_file: Option<PathBuf>,
    /// A checkpoint older than this (s, wall clock) is ignored.
    pub checkpoint_max_age_s: f64,
}

impl Default for LidarSimConfig {
    fn default() -> Self {
        LidarSimConfig {
            target: "deos".into(),
            scale: 1.0,
            scenario: ScenarioKind::Tumbling,
            seed: 0,
            compression: 1.0,
            range_m: 20.0,
            range_scale: 1.0,
            frames: 0,
            integration_time_s: SensorConfig::MID40_INTEGRATION_TIME_S,
            rate_hz: 1.0,
            clutter: true,
            echo_separation_m: spacepose_lidar_sim::config::DEFAULT_ECHO_SEPARATION_M,
            mismatch: None,
            truth_init: false,
            exit_at_end: false,
            sensor_id: 0,
            look_away: None,
            checkpoint_file: None,
            checkpoint_max_age_s: 60.0,
        }
    }
}

impl ServiceConfig for LidarSimConfig {
    fn validate(&self) -> Result<(), String> {
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!("{name} must be finite and > 0, got {v}"))
            }
        };
        positive("scale", self.scale)?;
        positive("range_m", self.range_m)?;
        positive("integration_time_s", self.integration_time_s)?;
        positive("checkpoint_max_age_s", self.checkpoint_max_age_s)?;
        if self.echo_separation_m.is_nan() || self.echo_separation_m <= 0.0 {
            return Err(format!(
                "echo_separation_m must be > 0 (inf: seed 004's average), got {}",
                self.echo_separation_m
            ));
        }
        if let Some(look) = &self.look_away {
            look.validate().map_err(|e| e.to_string())?;
        }
        if let Some(m) = &self.mismatch {
            m.validate().map_err(|e| e.to_string())?;
        }
        if !(self.range_scale.is_finite() && self.range_scale >= 1.0) {
            return Err(format!(
                "range_scale must be finite and >= 1, got {}",
                self.range_scale
            ));
        }
        if !(self.compression.is_finite() && self.compression >= 1.0) {
            return Err(format!(
                "compression must be >= 1, got {}",
                self.compression
            ));
        }
        if !(self.rate_hz.is_finite() && self.rate_hz >= 0.0) {
            return Err(format!(
                "rate_hz must be finite and >= 0, got {}",
                self.rate_hz
            ));
        }
        Ok(())
    }
}

impl LidarSimConfig {
    /// The frames this configuration describes: its target seen by a
    /// Livox Mid-40 model through its scenario, with the random streams of
    /// its seed. The sensor and any one-process evaluation of the same
    /// configuration get the same frames from it.
    ///
    /// # Errors
    /// A target that cannot be loaded, an invalid scenario or sensor.
    pub fn frame_source(&self) -> anyhow::Result<FrameSource> {
        let target = spacepose_prepare::resolve(&self.target, self.scale)
            .with_context(|| format!("cannot load target {:?}", self.target))?
            .target;
        let mut sc = ScenarioConfig::default_for(self.scenario);
        sc.seed = self.seed;
        sc.compression = self.compression;
        sc.range_m = self.range_m;
        sc.range_scale = self.range_scale;
        sc.random_frames = sc.random_frames.max(self.frames as usize);
        sc.look_away = self.look_away;
        let scenario = spacepose_scenario::build(&sc).context("invalid scenario")?;
        let mut sensor = SensorConfig::livox_mid40();
        sensor.integration_time_s = self.integration_time_s;
        sensor.effects.clutter = self.clutter;
        sensor.echo_separation_m = self.echo_separation_m;
        match &self.mismatch {
            None => FrameSource::new(Arc::new(target), scenario, sensor, self.seed),
            Some(m) => FrameSource::with_mismatch(&target, scenario, sensor, self.seed, m.clone()),
        }
        .context("invalid sensor or mismatch")
    }

    /// The frame period (ns); `None` when frames go out as fast as they are
    /// made (`rate_hz = 0`).
    pub fn period_ns(&self) -> Option<i64> {
        (self.rate_hz > 0.0).then(|| {
            let period = std::time::Duration::from_secs_f64(1.0 / self.rate_hz);
            i64::try_from(period.as_nanos()).unwrap_or(i64::MAX)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `deploy/examples/lidar-sim.toml` parses, validates and shows the
    /// defaults (but for the integration time it spells out).
    #[test]
    fn the_deploy_example_parses_and_shows_the_defaults() {
        let text = include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../deploy/examples/lidar-sim.toml"
        ));
        let c: LidarSimConfig = toml::from_str(text).unwrap();
        c.validate().unwrap();
        let defaults = LidarSimConfig {
            integration_time_s: c.integration_time_s,
            ..LidarSimConfig::default()
        };
        assert_eq!(c, defaults);
        LidarSimConfig::default().validate().unwrap();
    }

    #[test]
    fn a_mismatch_table_takes_defaults_and_refuses_bad_keys() {
        let c: LidarSimConfig = toml::from_str("[mismatch]\njitter_deg = 0.05\n").unwrap();
        c.validate().unwrap();
        let m = c.mismatch.unwrap();
        assert_eq!(m.jitter_deg, 0.05);
        assert_eq!(m.as_built, spacepose_model::AsBuilt::default());
        assert!(toml::from_str::<LidarSimConfig>("[mismatch]\njitter = 0.05\n").is_err());
        let bad: LidarSimConfig = toml::from_str("[mismatch.as_built]\nrelief_m = nan\n").unwrap();
        assert!(bad.validate().is_err());
    }

    #[test]
    fn unknown_keys_and_nan_fail() {
        assert!(toml::from_str::<LidarSimConfig>("rate = 2.0").is_err());
        let c: LidarSimConfig = toml::from_str("rate_hz = nan").unwrap();
        assert!(c.validate().unwrap_err().contains("rate_hz"));
        let c: LidarSimConfig = toml::from_str("scale = nan").unwrap();
        assert!(c.validate().unwrap_err().contains("scale"));
        let c: LidarSimConfig = toml::from_str("compression = 0.5").unwrap();
        assert!(c.validate().unwrap_err().contains("compression"));
        let c: LidarSimConfig = toml::from_str(
            "look_away = { first_frame = 8, frames = 4, angle_deg = 60.0 }\n\
             checkpoint_file = \"/tmp/x.sensorstate\"\n",
        )
        .unwrap();
        c.validate().unwrap();
        assert!(c.look_away.is_some() && c.checkpoint_file.is_some());
    }

    #[test]
    fn the_period_follows_the_rate() {
        let at = |rate_hz| LidarSimConfig {
            rate_hz,
            ..LidarSimConfig::default()
        };
        assert_eq!(at(0.0).period_ns(), None);
        assert_eq!(at(4.0).period_ns(), Some(250_000_000));
        assert_eq!(at(1.0).period_ns(), Some(1_000_000_000));
    }
}
