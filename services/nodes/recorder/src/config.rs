//! Configuration of the recorder service (TOML; keys in `README.md` and
//! `deploy/examples/recorder.toml`).

use crate::live_config::LiveConfig;
use serde::{Deserialize, Serialize};
use spacepose_foxglove::{Compression, RecordOptions};
use spacepose_runtime::ServiceConfig;
use std::path::PathBuf;

/// The recorder's configuration file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RecorderConfig {
    /// The MCAP file to write; `None`: no file (a live view only). When it
    /// exists (a restarted recorder), the recording goes on in
    /// `<stem>.1.mcap`, `<stem>.2.mcap`, ...
    pub file: Option<PathBuf>,
    /// Chunk compression: `"lz4"` (default), `"zstd"` or `"none"`.
    pub compression: Compression,
    /// Record the raw cloud of every n-th frame (by sequence); 0: none.
    pub raw_cloud_every: u64,
    /// Record the cropped cloud of every n-th frame; 0: none.
    pub cloud_every: u64,
    /// The target shown at the estimated and true poses, as the tracker
    /// names it (built-in, package directory or mesh file); `""`: none.
    pub target: String,
    /// Scale of a target mesh file (e.g. 0.001 for a model in mm).
    pub target_scale: f64,
    /// The deployment descriptor (TOML text), recorded as the attachment
    /// `descriptor.toml`, with each service's `config` as the metadata
    /// record `spacepose.config.<instance>`. `""`: none.
    pub descriptor: String,
    /// Scheduling niceness of the recorder (0-19): the recorder is off the
    /// frame path, so it yields the CPU to the services on it.
    pub nice: i32,
    /// The live view (a Foxglove WebSocket server); `None`: none.
    pub live: Option<LiveConfig>,
}

impl Default for RecorderConfig {
    fn default() -> Self {
        Self {
            file: None,
            compression: Compression::Lz4,
            raw_cloud_every: 1,
            cloud_every: 1,
            target: "deos".to_string(),
            target_scale: 1.0,
            descriptor: String::new(),
            nice: 10,
            live: None,
        }
    }
}

impl RecorderConfig {
    /// The recording options.
    pub fn options(&self) -> RecordOptions {
        RecordOptions {
            compression: self.compression,
            raw_cloud_every: self.raw_cloud_every,
            cloud_every: self.cloud_every,
        }
    }
}

impl ServiceConfig for RecorderConfig {
    fn validate(&self) -> Result<(), String> {
        match &self.file {
            None if self.live.is_none() => {
                return Err("neither a file nor a [live] view: nothing to do".into());
            }
            None => {}
            Some(f) if f.extension().is_none_or(|e| e != "mcap") => {
                return Err(format!("file {} must end in .mcap", f.display()));
            }
            Some(_) => {}
        }
        if let Some(live) = &self.live {
            live.validate().map_err(|e| format!("[live] {e}"))?;
        }
        if !(self.target_scale.is_finite() && self.target_scale > 0.0) {
            return Err(format!("target_scale = {} must be > 0", self.target_scale));
        }
        if !(0..=19).contains(&self.nice) {
            return Err(format!("nice = {} must be in 0..=19", self.nice));
        }
        if !self.descriptor.is_empty() {
            toml::from_str::<toml::Table>(&self.descriptor)
                .map_err(|e| format!("descriptor is not TOML: {e}"))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn valid() -> RecorderConfig {
        RecorderConfig {
            file: Some("run.mcap".into()),
            ..RecorderConfig::default()
        }
    }

    /// `deploy/examples/recorder.toml` parses, validates and shows the
    /// defaults (but for the file and the live view it spells out).
    #[test]
    fn the_deploy_example_parses_and_shows_the_defaults() {
        let text = include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../deploy/examples/recorder.toml"
        ));
        let c: RecorderConfig = toml::from_str(text).unwrap();
        c.validate().unwrap();
        assert_eq!(c.live, Some(LiveConfig::default()));
        let defaults = RecorderConfig {
            file: c.file.clone(),
            live: c.live.clone(),
            ..RecorderConfig::default()
        };
        assert_eq!(c, defaults);
    }

    #[test]
    fn a_file_or_a_live_view_is_needed_and_bad_values_are_named() {
        assert_eq!(valid().validate(), Ok(()));
        let e = RecorderConfig::default().validate().unwrap_err();
        assert!(e.contains("file") && e.contains("live"), "{e}");
        let live_only: RecorderConfig = toml::from_str("[live]\n").unwrap();
        assert_eq!(live_only.validate(), Ok(()));
        assert_eq!(live_only.file, None);
        let c: RecorderConfig =
            toml::from_str("file = \"/tmp/a.mcap\"\ncompression = \"zstd\"\ncloud_every = 5\n")
                .unwrap();
        assert_eq!(c.options().compression, Compression::Zstd);
        assert_eq!(
            (c.options().cloud_every, c.options().raw_cloud_every),
            (5, 1)
        );
        for (bad, field) in [
            (
                RecorderConfig {
                    target_scale: f64::NAN,
                    ..valid()
                },
                "target_scale",
            ),
            (
                RecorderConfig {
                    file: Some("a.bag".into()),
                    ..valid()
                },
                "file",
            ),
            (
                RecorderConfig {
                    descriptor: "x = = 1".into(),
                    ..valid()
                },
                "descriptor",
            ),
            (
                toml::from_str("[live]\nlisten = \"0.0.0.0:8765\"\n").unwrap(),
                "[live] listen",
            ),
        ] {
            let e = bad.validate().unwrap_err();
            assert!(e.contains(field), "{e}");
        }
        assert!(toml::from_str::<RecorderConfig>("every = 2\n").is_err());
        assert!(toml::from_str::<RecorderConfig>("compression = \"gzip\"\n").is_err());
        assert!(toml::from_str::<RecorderConfig>("[live]\nport = 1\n").is_err());
    }
}
