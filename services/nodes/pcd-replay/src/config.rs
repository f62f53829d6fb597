//! The service's configuration file (keys in `deploy/examples/pcd-replay.toml`).

use serde::Deserialize;
use spacepose_input::{InputOptions, TimeMapping};
use spacepose_runtime::ServiceConfig;
use std::path::PathBuf;
use std::time::Duration;

/// `spacepose-pcd-replay --config FILE`: the replay settings.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PcdReplayConfig {
    /// The recording: a directory of `frame_NNNNNN.pcd` / `.ply` (and
    /// `truth.csv`), an MCAP file or a ROS 2 bag (`spacepose_input::open`).
    /// The key `dir` is accepted for it too.
    #[serde(alias = "dir")]
    pub input: PathBuf,
    /// Point-cloud topic of an MCAP file or bag; unset: the only cloud
    /// channel, or the raw clouds of a spacepose recording.
    pub topic: Option<String>,
    /// Frames per second; 0 = at recorded speed (the recorded period of
    /// `truth.csv`, else the steps between scan starts), else 1 Hz.
    pub rate_hz: f64,
    /// Start again after the last frame.
    #[serde(rename = "loop")]
    pub looping: bool,
    /// Exit after the last frame (no loop); otherwise keep sending heartbeats.
    pub exit_at_end: bool,
    /// Sensor id written in the cloud headers.
    pub sensor_id: u16,
    /// Which field holds per-point times (`[time]`: `field`, `unit`, `base`).
    pub time: TimeMapping,
    /// Scan period (s) for derived times of frames without a time field
    /// and without a `truth.csv` row; unset: the recorded period, else 0.1 s.
    pub scan_period_s: Option<f64>,
}

impl Default for PcdReplayConfig {
    fn default() -> Self {
        PcdReplayConfig {
            input: PathBuf::from("frames"),
            topic: None,
            rate_hz: 0.0,
            looping: false,
            exit_at_end: false,
            sensor_id: 0,
            time: TimeMapping::default(),
            scan_period_s: None,
        }
    }
}

impl ServiceConfig for PcdReplayConfig {
    fn validate(&self) -> Result<(), String> {
        if !(self.rate_hz.is_finite() && self.rate_hz >= 0.0) {
            return Err(format!(
                "rate_hz must be finite and >= 0, got {}",
                self.rate_hz
            ));
        }
        if self.input.as_os_str().is_empty() {
            return Err("input must not be empty".into());
        }
        self.input_options().validate()
    }
}

impl PcdReplayConfig {
    /// How the recording is read: the topic, time mapping and scan period.
    pub fn input_options(&self) -> InputOptions {
        InputOptions {
            topic: self.topic.clone(),
            time: self.time.clone(),
            scan_period_s: self.scan_period_s,
        }
    }

    /// The frame period: `1 / rate_hz`, else the recording's (`recorded_s`,
    /// from `truth.csv`), else 1 s (the step when scan starts give none).
    pub fn period(&self, recorded_s: Option<f64>) -> Duration {
        let one_second = Duration::from_secs(1);
        if self.rate_hz > 0.0 {
            Duration::try_from_secs_f64(1.0 / self.rate_hz).unwrap_or(one_second)
        } else {
            recorded_s
                .and_then(|s| Duration::try_from_secs_f64(s).ok())
                .unwrap_or(one_second)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `deploy/examples/pcd-replay.toml` parses and shows the defaults.
    #[test]
    fn the_deploy_example_parses_and_shows_the_defaults() {
        let text = include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../deploy/examples/pcd-replay.toml"
        ));
        let c: PcdReplayConfig = toml::from_str(text).unwrap();
        c.validate().unwrap();
        assert_eq!(c, PcdReplayConfig::default());
    }

    #[test]
    fn keys_parse_and_bad_values_fail() {
        let c: PcdReplayConfig =
            toml::from_str("dir = \"rec\"\nrate_hz = 4.0\nloop = true\nsensor_id = 3\n").unwrap();
        assert_eq!(
            (c.input.to_str(), c.looping, c.sensor_id),
            (Some("rec"), true, 3)
        );
        assert!(toml::from_str::<PcdReplayConfig>("looping = true").is_err());
        let c: PcdReplayConfig = toml::from_str("rate_hz = nan").unwrap();
        assert!(c.validate().unwrap_err().contains("rate_hz"));
        let c: PcdReplayConfig = toml::from_str("input = \"\"").unwrap();
        assert!(c.validate().unwrap_err().contains("input"));
        let c: PcdReplayConfig =
            toml::from_str("input = \"run.mcap\"\ntopic = \"/points\"").unwrap();
        assert_eq!(c.input_options().topic.as_deref(), Some("/points"));
        let c: PcdReplayConfig = toml::from_str("scan_period_s = nan").unwrap();
        assert!(c.validate().unwrap_err().contains("scan_period_s"));
        let c: PcdReplayConfig =
            toml::from_str("[time]\nfield = \"offset_time\"\nunit = \"ns\"\nbase = \"relative\"\n")
                .unwrap();
        assert_eq!(c.time.field.as_deref(), Some("offset_time"));
        assert!(toml::from_str::<PcdReplayConfig>("[time]\nunits = \"ns\"").is_err());
    }

    #[test]
    fn the_period_is_the_rate_the_recording_or_a_second() {
        let at = |rate_hz| PcdReplayConfig {
            rate_hz,
            ..PcdReplayConfig::default()
        };
        assert_eq!(at(25.0).period(Some(2.0)), Duration::from_millis(40));
        assert_eq!(at(0.0).period(Some(0.5)), Duration::from_millis(500));
        assert_eq!(at(0.0).period(None), Duration::from_secs(1));
    }
}
