//! The topic check of a descriptor: who produces each topic (a lidar-sim
//! with the truth acquisition, a bridge's inbound routes) and whether every
//! required input has a producer.

use super::descriptor::Descriptor;
use spacepose_messages::{ServiceKind, Topic};
use std::collections::HashMap;

/// True when lidar-sim's config asks for the truth acquisition.
pub fn truth_init(config: &toml::Table) -> bool {
    config
        .get("truth_init")
        .and_then(toml::Value::as_bool)
        .unwrap_or(false)
}

/// The topics a bridge instance publishes on its host (its inbound
/// routes), read from its config (for the topic check of a host's part).
pub fn bridge_outputs(config: &toml::Table) -> Vec<Topic> {
    let mut out: Vec<Topic> = config
        .get("routes")
        .and_then(toml::Value::as_array)
        .into_iter()
        .flatten()
        .filter(|r| r.get("direction").and_then(toml::Value::as_str) == Some("from-zenoh"))
        .filter_map(|r| r.get("topic").and_then(toml::Value::as_str))
        .filter_map(Topic::parse)
        .collect();
    out.push(Topic::Health);
    out
}

/// Every required input has a producer among the descriptor's services (a
/// host part's bridge produces its inbound routes).
pub(super) fn check_topics(descriptor: &Descriptor, problems: &mut Vec<String>) {
    let mut producers: HashMap<Topic, Vec<&str>> = HashMap::new();
    for s in &descriptor.services {
        let outputs = match s.kind {
            ServiceKind::Bridge => bridge_outputs(&s.config),
            kind => kind.outputs(truth_init(&s.config)),
        };
        for t in outputs {
            producers.entry(t).or_default().push(&s.name);
        }
    }
    for s in &descriptor.services {
        for t in s.kind.required_inputs() {
            if producers
                .get(&t)
                .is_some_and(|p| p.iter().any(|n| *n != s.name))
            {
                continue;
            }
            let kinds: Vec<String> = ServiceKind::producers_of(t)
                .iter()
                .map(|k| {
                    if *k == ServiceKind::LidarSim && t == Topic::Acquisition {
                        "lidar-sim with truth_init = true".to_string()
                    } else {
                        k.to_string()
                    }
                })
                .collect();
            problems.push(format!(
                "service {:?} ({}) reads topic {:?} but no service of the descriptor publishes it \
                 (add one of: {})",
                s.name,
                s.kind,
                t.as_str(),
                kinds.join(", ")
            ));
        }
    }
}
