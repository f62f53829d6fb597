//! The topic graph: the kinds of process a deployment can start, and which
//! topics each one reads and publishes.
//!
//! This is the one declaration of the graph. The service runtime opens a
//! subscriber for every input and a publisher for every output of its
//! kind, in this order; `spacepose up` checks a descriptor against it
//! (every required input has a producer); the end-to-end tests and the
//! in-process suite of `spacepose eval` read it too.

use crate::names::Topic;
use serde::{Deserialize, Serialize};

/// A service kind: one binary each.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ServiceKind {
    /// Simulated sensor (`spacepose-lidar-sim`).
    LidarSim,
    /// Replay of a directory of PCD/PLY frames (`spacepose-pcd-replay`).
    PcdReplay,
    /// Validation and crop to the target's region of interest (`spacepose-ingest`).
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
    /// The run into an MCAP file with Foxglove schemas (`spacepose-recorder`);
    /// added by `spacepose demo --record` and `spacepose up --record`.
    Recorder,
}

/// Whether a service can do its job without an input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Need {
    /// Each one needs a producer in the descriptor.
    Required,
    /// Used when present; its absence degrades, not breaks.
    Optional,
}

use Need::{Optional, Required};

impl ServiceKind {
    /// Every kind.
    pub const ALL: [ServiceKind; 9] = [
        ServiceKind::LidarSim,
        ServiceKind::PcdReplay,
        ServiceKind::Ingest,
        ServiceKind::Tracker,
        ServiceKind::Filter,
        ServiceKind::Telemetry,
        ServiceKind::Init,
        ServiceKind::Bridge,
        ServiceKind::Recorder,
    ];

    /// The descriptor spelling (`"lidar-sim"`, ...), also the service name
    /// in health messages.
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
            ServiceKind::Recorder => "recorder",
        }
    }

    /// Parses [`ServiceKind::as_str`] back.
    pub fn parse(s: &str) -> Option<ServiceKind> {
        ServiceKind::ALL.into_iter().find(|k| k.as_str() == s)
    }

    /// File name of the binary (`"spacepose-lidar-sim"`, ...).
    pub fn binary_name(self) -> String {
        format!("spacepose-{}", self.as_str())
    }

    /// Cargo package that builds the binary (`services/nodes/<kind>`).
    pub fn package(self) -> String {
        format!("spacepose-{}-node", self.as_str())
    }

    /// Sources publish frames on their own clock: they start last, once every
    /// consumer is listening, so no frame is published into the void.
    pub fn is_source(self) -> bool {
        matches!(self, ServiceKind::LidarSim | ServiceKind::PcdReplay)
    }

    /// The topics the service reads, in the order it takes them when
    /// several are waiting: a runtime drains every message topic in this
    /// order, and again before each cloud, so that control sent before a
    /// cloud applies to it.
    pub fn inputs(self) -> &'static [(Topic, Need)] {
        match self {
            ServiceKind::LidarSim | ServiceKind::PcdReplay => &[],
            // The prediction that centres the crop: the filter's state, or
            // the position of an acquisition (the later one wins).
            ServiceKind::Ingest => &[
                (Topic::FilterState, Optional),
                (Topic::Acquisition, Optional),
                (Topic::RawCloud, Required),
            ],
            // The first pose comes from the init service (or lidar-sim's
            // `truth_init = true`).
            ServiceKind::Tracker => &[
                (Topic::Command, Optional),
                (Topic::Acquisition, Required),
                (Topic::FilterState, Optional),
                (Topic::Cloud, Required),
            ],
            ServiceKind::Filter => &[
                (Topic::Command, Optional),
                (Topic::Acquisition, Optional),
                (Topic::Pose, Required),
            ],
            ServiceKind::Telemetry => &[
                (Topic::Truth, Optional),
                (Topic::Pose, Optional),
                (Topic::FilterState, Optional),
                (Topic::Health, Required),
            ],
            // Without tracker poses it acquires once and never hears of a loss.
            ServiceKind::Init => &[(Topic::Pose, Optional), (Topic::Cloud, Required)],
            // Its routes are in its config (`spacepose up` plans them).
            ServiceKind::Bridge => &[],
            // Everything a run is made of; whatever the deployment has.
            ServiceKind::Recorder => &[
                (Topic::Truth, Optional),
                (Topic::Acquisition, Optional),
                (Topic::Pose, Optional),
                (Topic::FilterState, Optional),
                (Topic::Health, Optional),
                (Topic::RawCloud, Optional),
                (Topic::Cloud, Optional),
            ],
        }
    }

    /// Topics without which the service cannot do its job.
    pub fn required_inputs(self) -> impl Iterator<Item = Topic> {
        self.inputs()
            .iter()
            .filter(|(_, n)| *n == Required)
            .map(|(t, _)| *t)
    }

    /// True when the service reads `topic`.
    pub fn reads(self, topic: Topic) -> bool {
        self.inputs().iter().any(|(t, _)| *t == topic)
    }

    /// Topics published. `truth_init` says whether a lidar-sim publishes the
    /// truth acquisition of its first frame (its config key `truth_init`);
    /// the runtime opens them all.
    pub fn outputs(self, truth_init: bool) -> Vec<Topic> {
        let mut out = match self {
            ServiceKind::LidarSim => vec![Topic::RawCloud, Topic::Truth],
            ServiceKind::PcdReplay => vec![Topic::RawCloud],
            ServiceKind::Ingest => vec![Topic::Cloud],
            ServiceKind::Tracker => vec![Topic::Pose],
            ServiceKind::Filter => vec![Topic::FilterState],
            // JSON on zenoh; the ground's commands come in through its
            // command route.
            ServiceKind::Telemetry => vec![Topic::Command],
            ServiceKind::Init => vec![Topic::Acquisition],
            // Its inbound routes, from its config.
            ServiceKind::Bridge => vec![],
            ServiceKind::Recorder => vec![],
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
                    !ServiceKind::producers_of(topic).is_empty(),
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
        assert_eq!(
            ServiceKind::Init.required_inputs().collect::<Vec<_>>(),
            [Topic::Cloud]
        );
        assert_eq!(ServiceKind::Init.binary_name(), "spacepose-init");
        assert_eq!(ServiceKind::Init.package(), "spacepose-init-node");
    }

    #[test]
    fn names_round_trip_and_every_topic_is_read_by_someone() {
        for kind in ServiceKind::ALL {
            assert_eq!(ServiceKind::parse(kind.as_str()), Some(kind));
            assert_eq!(kind.binary_name(), format!("spacepose-{kind}"));
            let inputs = kind.inputs();
            for (i, (t, _)) in inputs.iter().enumerate() {
                assert!(
                    !inputs[..i].iter().any(|(u, _)| u == t),
                    "{kind}: {t:?} twice"
                );
            }
        }
        for topic in Topic::ALL {
            let read = ServiceKind::ALL.iter().any(|k| k.reads(topic));
            // Health and commands also go to the CLI; truth to the scorers.
            assert!(
                read || topic == Topic::Command,
                "{topic:?} is read by no service"
            );
        }
    }
}
