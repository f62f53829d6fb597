//! The kinds of service a deployment can start, with the topics each one
//! reads and publishes (the topic check of a descriptor relies on them).

use serde::{Deserialize, Serialize};
use spacepose_messages::Topic;

/// A service kind: one binary each.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ServiceKind {
    /// Simulated sensor (`spacepose-lidar-sim`).
    LidarSim,
    /// Replay of a directory of PCD/PLY frames (`spacepose-pcd-replay`).
    PcdReplay,
    /// Crop to the region of interest and voxel filter (`spacepose-ingest`).
    Ingest,
    /// Pose tracking (`spacepose-tracker`).
    Tracker,
    /// Relative-motion filter (`spacepose-filter`).
    Filter,
    /// Health, pose and truth to zenoh JSON (`spacepose-telemetry`).
    Telemetry,
    /// Pose acquisition at start and after a loss (`spacepose-init`).
    Init,
    /// The topics that cross hosts, over zenoh (`spacepose-bridge`); added
    /// by `spacepose up --host` to each host's part of a partitioned
    /// deployment, never written in a descriptor.
    Bridge,
}

impl ServiceKind {
    /// Every kind.
    pub const ALL: [ServiceKind; 8] = [
        ServiceKind::LidarSim,
        ServiceKind::PcdReplay,
        ServiceKind::Ingest,
        ServiceKind::Tracker,
        ServiceKind::Filter,
        ServiceKind::Telemetry,
        ServiceKind::Init,
        ServiceKind::Bridge,
    ];

    /// The descriptor spelling (`"lidar-sim"`, ...).
    pub fn as_str(self) -> &'static str {
        match self {
            ServiceKind::LidarSim => "lidar-sim",
            ServiceKind::PcdReplay => "pcd-replay",
            ServiceKind::Ingest => "ingest",
            ServiceKind::Tracker => "tracker",
            ServiceKind::Filter => "filter",
            ServiceKind::Telemetry => "telemetry",
            ServiceKind::Init => "init",
            ServiceKind::Bridge => "bridge",
        }
    }

    /// File name of the binary (`"spacepose-lidar-sim"`, ...).
    pub fn binary_name(self) -> String {
        format!("spacepose-{}", self.as_str())
    }

    /// Cargo package that builds the binary.
    pub fn package(self) -> String {
        self.binary_name()
    }

    /// Sources publish frames on their own clock: they start last, once every
    /// consumer is listening, so no frame is published into the void.
    pub fn is_source(self) -> bool {
        matches!(self, ServiceKind::LidarSim | ServiceKind::PcdReplay)
    }

    /// Topics without which the service cannot do its job: each one needs a
    /// producer in the descriptor.
    pub fn required_inputs(self) -> &'static [Topic] {
        match self {
            ServiceKind::LidarSim | ServiceKind::PcdReplay | ServiceKind::Bridge => &[],
            ServiceKind::Ingest => &[Topic::RawCloud],
            // The first pose comes from the init service (or, the old
            // documented path, lidar-sim's `truth_init = true`).
            ServiceKind::Tracker => &[Topic::Cloud, Topic::Acquisition],
            ServiceKind::Filter => &[Topic::Pose],
            ServiceKind::Telemetry => &[Topic::Health],
            ServiceKind::Init => &[Topic::Cloud],
        }
    }

    /// Topics used when present (their absence degrades, not breaks).
    pub fn optional_inputs(self) -> &'static [Topic] {
        match self {
            ServiceKind::LidarSim | ServiceKind::PcdReplay => &[Topic::Command],
            ServiceKind::Ingest => &[Topic::FilterState],
            ServiceKind::Tracker => &[Topic::FilterState, Topic::Command],
            ServiceKind::Filter => &[Topic::Acquisition, Topic::Command],
            ServiceKind::Telemetry => &[Topic::Pose, Topic::FilterState, Topic::Truth],
            // Without tracker poses it acquires once and never hears of a loss.
            ServiceKind::Init => &[Topic::Pose],
            // Its routes are in its config (`partition::bridge_outputs`).
            ServiceKind::Bridge => &[],
        }
    }

    /// Topics published. `truth_init` says whether a lidar-sim publishes the
    /// truth acquisition of its first frame (its config key `truth_init`).
    pub fn outputs(self, truth_init: bool) -> Vec<Topic> {
        let mut out = match self {
            ServiceKind::LidarSim => vec![Topic::RawCloud, Topic::Truth],
            ServiceKind::PcdReplay => vec![Topic::RawCloud],
            ServiceKind::Ingest => vec![Topic::Cloud],
            ServiceKind::Tracker => vec![Topic::Pose],
            ServiceKind::Filter => vec![Topic::FilterState],
            // JSON on zenoh; the ground's commands come in through its
            // command bridge.
            ServiceKind::Telemetry => vec![Topic::Command],
            ServiceKind::Init => vec![Topic::Acquisition],
            // Its inbound routes (`partition::bridge_outputs`).
            ServiceKind::Bridge => vec![],
        };
        if self == ServiceKind::LidarSim && truth_init {
            out.push(Topic::Acquisition);
        }
        out.push(Topic::Health);
        out
    }

    /// Kinds that can publish `topic` (for error messages).
    pub fn producers_of(topic: Topic) -> Vec<ServiceKind> {
        ServiceKind::ALL
            .into_iter()
            .filter(|k| k.outputs(true).contains(&topic))
            .collect()
    }
}

impl std::fmt::Display for ServiceKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_required_input_has_a_possible_producer() {
        for kind in ServiceKind::ALL {
            for topic in kind.required_inputs() {
                assert!(
                    !ServiceKind::producers_of(*topic).is_empty(),
                    "{kind} needs {topic:?}"
                );
            }
        }
        assert_eq!(
            ServiceKind::producers_of(Topic::Cloud),
            vec![ServiceKind::Ingest]
        );
        assert!(
            !ServiceKind::LidarSim
                .outputs(false)
                .contains(&Topic::Acquisition)
        );
        assert!(
            ServiceKind::LidarSim
                .outputs(true)
                .contains(&Topic::Acquisition)
        );
    }

    #[test]
    fn the_init_service_feeds_the_tracker_without_truth() {
        assert!(ServiceKind::producers_of(Topic::Acquisition).contains(&ServiceKind::Init));
        assert_eq!(
            ServiceKind::Init.outputs(false),
            vec![Topic::Acquisition, Topic::Health]
        );
        assert_eq!(ServiceKind::Init.required_inputs(), &[Topic::Cloud]);
        assert_eq!(ServiceKind::Init.binary_name(), "spacepose-init");
    }

    #[test]
    fn names_round_trip_through_serde() {
        for kind in ServiceKind::ALL {
            let v: ServiceKind = toml::Value::String(kind.as_str().into())
                .try_into()
                .unwrap();
            assert_eq!(v, kind);
            assert_eq!(kind.binary_name(), format!("spacepose-{kind}"));
        }
    }
}
