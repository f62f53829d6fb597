//! Deployment-prefixed iceoryx2 service names and zenoh keys.
//!
//! Every name carries the deployment prefix so that two suites on one
//! machine (or on one zenoh network) never meet: iceoryx2 service names are
//! `"{prefix}/{producer}/{topic}"`, the iceoryx2 `config.global.prefix` is
//! [`Names::iceoryx2_prefix`], and zenoh keys are `"spacepose/{prefix}/{topic}"`.

use crate::error::MessageError;
use serde::{Deserialize, Serialize};

/// Longest accepted deployment prefix.
pub const MAX_PREFIX_LEN: usize = 32;

/// A topic of the suite (one iceoryx2 service each).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Topic {
    /// Raw frames from the sensor (or simulator / replay): `CloudHeader` + `[WirePoint]`.
    RawCloud,
    /// Frames cropped to the target by ingest (the raw points, not voxel-filtered): `CloudHeader` + `[WirePoint]`.
    Cloud,
    /// `PoseEstimate` from the tracker(s).
    Pose,
    /// `FilterState` from the filter service.
    FilterState,
    /// `AcquisitionResult` from the initialisation service (or lidar-sim's truth init).
    Acquisition,
    /// `TruthMsg` from the simulator (scoring only).
    Truth,
    /// `Health` heartbeats from every service.
    Health,
    /// `Command`s (reinit, mode, swap) from the ground or the CLI.
    Command,
}

impl Topic {
    /// Every topic, in a fixed order.
    pub const ALL: [Topic; 8] = [
        Topic::RawCloud,
        Topic::Cloud,
        Topic::Pose,
        Topic::FilterState,
        Topic::Acquisition,
        Topic::Truth,
        Topic::Health,
        Topic::Command,
    ];

    /// Short snake_case name (`"raw_cloud"`, `"pose"`, ...), used in zenoh keys and configs.
    pub fn as_str(self) -> &'static str {
        match self {
            Topic::RawCloud => "raw_cloud",
            Topic::Cloud => "cloud",
            Topic::Pose => "pose",
            Topic::FilterState => "filter_state",
            Topic::Acquisition => "acquisition",
            Topic::Truth => "truth",
            Topic::Health => "health",
            Topic::Command => "command",
        }
    }

    /// Parses [`Topic::as_str`] back.
    pub fn parse(s: &str) -> Option<Topic> {
        Topic::ALL.into_iter().find(|t| t.as_str() == s)
    }

    /// True for the slice (cloud) topics.
    pub fn is_cloud(self) -> bool {
        matches!(self, Topic::RawCloud | Topic::Cloud)
    }

    /// Service path below the prefix (`"ingest/cloud"`, ...).
    fn service_suffix(self) -> &'static str {
        match self {
            Topic::RawCloud => "sensor/raw_cloud",
            Topic::Cloud => "ingest/cloud",
            Topic::Pose => "tracker/pose",
            Topic::FilterState => "filter/state",
            Topic::Acquisition => "acquisition/result",
            Topic::Truth => "sim/truth",
            Topic::Health => "health",
            Topic::Command => "command",
        }
    }
}

/// Checks a deployment prefix: `[a-z0-9_-]{1,32}`.
pub fn validate_prefix(prefix: &str) -> Result<(), MessageError> {
    let err = |reason| MessageError::InvalidPrefix {
        prefix: prefix.to_string(),
        reason,
    };
    if prefix.is_empty() {
        return Err(err("empty"));
    }
    if prefix.len() > MAX_PREFIX_LEN {
        return Err(err("longer than 32 characters"));
    }
    if !prefix
        .bytes()
        .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_' || b == b'-')
    {
        return Err(err("only a-z, 0-9, '_' and '-' are allowed"));
    }
    Ok(())
}

/// All names of one deployment.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Names {
    prefix: String,
}

impl Names {
    /// Names for the deployment `prefix` (`[a-z0-9_-]{1,32}`).
    pub fn new(prefix: &str) -> Result<Names, MessageError> {
        validate_prefix(prefix)?;
        Ok(Names {
            prefix: prefix.to_string(),
        })
    }

    /// The deployment prefix.
    pub fn prefix(&self) -> &str {
        &self.prefix
    }

    /// iceoryx2 `config.global.prefix`: `"sp_{prefix}_"`, so the shared-memory
    /// files of two deployments never collide (`/dev/shm/sp_{prefix}_*`).
    pub fn iceoryx2_prefix(&self) -> String {
        format!("sp_{}_", self.prefix)
    }

    /// iceoryx2 service name of a topic: `"{prefix}/{producer}/{topic}"`.
    pub fn service(&self, topic: Topic) -> String {
        format!("{}/{}", self.prefix, topic.service_suffix())
    }

    /// Raw sensor frames (`"{prefix}/sensor/raw_cloud"`).
    pub fn raw_cloud(&self) -> String {
        self.service(Topic::RawCloud)
    }
    /// Cropped frames from ingest (`"{prefix}/ingest/cloud"`).
    pub fn cloud(&self) -> String {
        self.service(Topic::Cloud)
    }
    /// Pose estimates (`"{prefix}/tracker/pose"`).
    pub fn pose(&self) -> String {
        self.service(Topic::Pose)
    }
    /// Filter state (`"{prefix}/filter/state"`).
    pub fn filter_state(&self) -> String {
        self.service(Topic::FilterState)
    }
    /// Acquisition results (`"{prefix}/acquisition/result"`).
    pub fn acquisition(&self) -> String {
        self.service(Topic::Acquisition)
    }
    /// Simulator truth (`"{prefix}/sim/truth"`).
    pub fn truth(&self) -> String {
        self.service(Topic::Truth)
    }
    /// Health heartbeats (`"{prefix}/health"`).
    pub fn health(&self) -> String {
        self.service(Topic::Health)
    }
    /// Commands (`"{prefix}/command"`).
    pub fn command(&self) -> String {
        self.service(Topic::Command)
    }

    /// A zenoh key below this deployment: `"spacepose/{prefix}/{topic}"`
    /// (e.g. `zenoh_key("telemetry/pose")`).
    pub fn zenoh_key(&self, topic: &str) -> String {
        format!("spacepose/{}/{}", self.prefix, topic)
    }

    /// The zenoh key on which the bridge carries a topic in the postcard codec:
    /// `"spacepose/{prefix}/wire/{topic}"`.
    pub fn wire_key(&self, topic: Topic) -> String {
        self.zenoh_key(&format!("wire/{}", topic.as_str()))
    }

    /// The zenoh key of a JSON telemetry stream: `"spacepose/{prefix}/telemetry/{what}"`.
    pub fn telemetry_key(&self, what: &str) -> String {
        self.zenoh_key(&format!("telemetry/{what}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prefixes_are_validated() {
        assert!(Names::new("demo").is_ok());
        assert!(Names::new("a-b_9").is_ok());
        assert!(Names::new(&"x".repeat(32)).is_ok());
        for bad in ["", "Demo", "a/b", "a b", "é", "a.b", &"x".repeat(33)] {
            assert!(
                matches!(Names::new(bad), Err(MessageError::InvalidPrefix { .. })),
                "{bad:?} accepted"
            );
        }
    }

    #[test]
    fn names_carry_the_prefix() {
        let n = Names::new("suite1").unwrap();
        assert_eq!(n.cloud(), "suite1/ingest/cloud");
        assert_eq!(n.raw_cloud(), "suite1/sensor/raw_cloud");
        assert_eq!(
            n.zenoh_key("telemetry/pose"),
            "spacepose/suite1/telemetry/pose"
        );
        assert_eq!(n.telemetry_key("pose"), "spacepose/suite1/telemetry/pose");
        assert_eq!(n.wire_key(Topic::Command), "spacepose/suite1/wire/command");
        assert_eq!(n.iceoryx2_prefix(), "sp_suite1_");
        let other = Names::new("suite2").unwrap();
        for t in Topic::ALL {
            assert!(n.service(t).starts_with("suite1/"));
            assert_ne!(n.service(t), other.service(t));
        }
    }

    #[test]
    fn topic_names_round_trip_and_are_distinct() {
        let n = Names::new("p").unwrap();
        let mut seen = std::collections::HashSet::new();
        for t in Topic::ALL {
            assert_eq!(Topic::parse(t.as_str()), Some(t));
            assert!(seen.insert(n.service(t)));
        }
        assert_eq!(Topic::parse("nope"), None);
    }
}
