//! Partitioned deployments: one descriptor split over hosts, one part per
//! host started with `spacepose up --host NAME`.
//!
//! Each host's part is an ordinary deployment under its own local prefix
//! (its own iceoryx2 prefix, run directory and supervisor), plus one
//! `bridge-{host}` instance (`spacepose-bridge`) that joins the zenoh link
//! and forwards the topics that cross hosts on the suite's link keys
//! `spacepose/{prefix}/link/{topic}`.
//!
//! Which topics cross, and which way, follows from the descriptor: a topic
//! goes *to* the link on a host that produces it for a service of another
//! host, and comes *from* the link on a host that consumes it while another
//! host produces it. A topic goes one way per host (a host that both needs
//! a topic from the link and sends its own to another host would loop it):
//! such a descriptor is refused. Producers and consumers are the services'
//! topics ([`ServiceKind::outputs`], inputs); the telemetry service produces
//! the ground's commands. Commands a host's supervisor publishes (swaps)
//! stay on that host.

use super::descriptor::{Descriptor, HostEntry, ServiceEntry};
use super::problems::Problems;
use super::topics::{check_topics, truth_init};
use spacepose_messages::ServiceKind;
use spacepose_messages::{Names, Topic};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

pub use super::topics::bridge_outputs;

/// Direction of a crossing topic on one host.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Crossing {
    /// Produced here for another host.
    Out,
    /// Consumed here, produced on another host.
    In,
}

/// The local prefix of a host's part.
pub fn host_prefix(d: &Descriptor, h: &HostEntry) -> String {
    h.prefix
        .clone()
        .unwrap_or_else(|| format!("{}-{}", d.prefix, h.name))
}

/// The bridge instance name of a host.
pub fn bridge_name(host: &str) -> String {
    format!("bridge-{host}")
}

fn hosts_where(d: &Descriptor, mut uses: impl FnMut(&ServiceEntry) -> bool) -> BTreeSet<&str> {
    d.services
        .iter()
        .filter(|s| uses(s))
        .filter_map(|s| s.host.as_deref())
        .collect()
}

/// The topics crossing `host`, in `Topic::ALL` order; conflicts (a topic
/// that would have to go both ways) are pushed to `problems`.
pub fn crossings(d: &Descriptor, host: &str, problems: &mut Vec<String>) -> Vec<(Topic, Crossing)> {
    let mut out = Vec::new();
    for topic in Topic::ALL {
        let producers = hosts_where(d, |s| {
            s.kind.outputs(truth_init(&s.config)).contains(&topic)
        });
        let consumers = hosts_where(d, |s| s.kind.reads(topic));
        let others = |set: &BTreeSet<&str>| set.iter().any(|h| *h != host);
        let send = producers.contains(host) && others(&consumers);
        let receive = consumers.contains(host) && others(&producers);
        match (send, receive) {
            (true, true) => problems.push(format!(
                "topic {:?} would cross host {host:?} both ways (it is produced there for \
                 another host and also needed there from another host): keep its producers \
                 on one host",
                topic.as_str()
            )),
            (true, false) => out.push((topic, Crossing::Out)),
            (false, true) => out.push((topic, Crossing::In)),
            (false, false) => {}
        }
    }
    out
}

fn resolve(base: &Path, p: &Path) -> PathBuf {
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        base.join(p)
    }
}

fn strings(v: &[String]) -> toml::Value {
    toml::Value::Array(v.iter().cloned().map(toml::Value::String).collect())
}

/// The bridge instance of `h` forwarding `routes`.
fn bridge_entry(
    d: &Descriptor,
    h: &HostEntry,
    routes: &[(Topic, Crossing)],
    base: &Path,
) -> ServiceEntry {
    let mut zenoh = toml::Table::new();
    zenoh.insert("mode".into(), toml::Value::String(h.mode.clone()));
    zenoh.insert("listen".into(), strings(&h.listen));
    zenoh.insert("connect".into(), strings(&h.connect));
    let routes: Vec<toml::Value> = routes
        .iter()
        .map(|(topic, dir)| {
            let mut r = toml::Table::new();
            r.insert("topic".into(), toml::Value::String(topic.as_str().into()));
            let dir = match dir {
                Crossing::Out => "to-zenoh",
                Crossing::In => "from-zenoh",
            };
            r.insert("direction".into(), toml::Value::String(dir.into()));
            if let (true, Some(hz)) = (topic.is_cloud(), d.link.cloud_rate_hz) {
                r.insert("max_rate_hz".into(), toml::Value::Float(hz));
            }
            toml::Value::Table(r)
        })
        .collect();
    let mut config = toml::Table::new();
    config.insert("suite_prefix".into(), toml::Value::String(d.prefix.clone()));
    config.insert("zenoh".into(), toml::Value::Table(zenoh));
    config.insert("routes".into(), toml::Value::Array(routes));
    config.insert(
        "wait_for_link_s".into(),
        toml::Value::Float(h.wait_for_link_s),
    );
    if let Some(c) = &h.credentials_file {
        let path = resolve(base, c).display().to_string();
        config.insert("credentials_file".into(), toml::Value::String(path));
    }
    if let Some(dict) = &d.link.dictionary_file {
        let mut access = toml::Table::new();
        let path = resolve(base, dict).display().to_string();
        access.insert("dictionary_file".into(), toml::Value::String(path));
        access.insert("peers".into(), strings(&d.link.peers));
        config.insert("access".into(), toml::Value::Table(access));
    }
    ServiceEntry {
        name: bridge_name(&h.name),
        kind: ServiceKind::Bridge,
        binary: None,
        host: None,
        restart_policy: None,
        config,
    }
}

fn check_hosts(d: &Descriptor, problems: &mut Vec<String>) {
    let mut seen = BTreeSet::new();
    for h in &d.hosts {
        let ok = (1..=12).contains(&h.name.len())
            && h.name
                .bytes()
                .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-');
        if !ok {
            problems.push(format!(
                "host name {:?}: use 1-12 characters of a-z, 0-9 and '-'",
                h.name
            ));
        }
        if !seen.insert(h.name.as_str()) {
            problems.push(format!("host {:?} is listed twice", h.name));
        }
        let prefix = host_prefix(d, h);
        if let Err(e) = Names::new(&prefix) {
            problems.push(format!("host {:?}: local prefix {prefix:?}: {e}", h.name));
        }
        if d.services.iter().any(|s| s.name == bridge_name(&h.name)) {
            problems.push(format!(
                "service name {:?} is reserved for the bridge of host {:?}",
                bridge_name(&h.name),
                h.name
            ));
        }
    }
    let prefixes: BTreeSet<String> = d.hosts.iter().map(|h| host_prefix(d, h)).collect();
    if prefixes.len() < d.hosts.len() {
        problems.push("two hosts have the same local prefix".to_string());
    }
    for s in &d.services {
        match &s.host {
            None => problems.push(format!(
                "service {:?} has no host (every service of a partitioned deployment names one)",
                s.name
            )),
            Some(h) if !seen.contains(h.as_str()) => problems.push(format!(
                "service {:?}: unknown host {h:?} (hosts: {})",
                s.name,
                d.hosts
                    .iter()
                    .map(|h| h.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
            Some(_) => {}
        }
    }
    if d.link.dictionary_file.is_some() && d.link.peers.is_empty() {
        problems.push("[link] has a dictionary_file but no peers".to_string());
    }
}

/// The part of partitioned descriptor `d` that runs on `host`: its
/// services under the host's local prefix, plus its bridge. `base` is the
/// descriptor's directory (relative files). Every problem of the whole
/// descriptor is reported (topics, hosts, conflicts on any host).
pub fn host_part(d: &Descriptor, host: &str, base: &Path) -> Result<Descriptor, Problems> {
    let mut problems = Vec::new();
    if d.hosts.is_empty() {
        return Err(Problems(vec![
            "--host given, but the descriptor has no [[host]] tables".to_string(),
        ]));
    }
    check_hosts(d, &mut problems);
    check_topics(d, &mut problems);
    let mut routes = Vec::new();
    for h in &d.hosts {
        let r = crossings(d, &h.name, &mut problems);
        if h.name == host {
            routes = r;
        }
    }
    let Some(h) = d.hosts.iter().find(|h| h.name == host) else {
        problems.push(format!(
            "unknown host {host:?} (hosts: {})",
            d.hosts
                .iter()
                .map(|h| h.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        ));
        return Err(Problems(problems));
    };
    if !problems.is_empty() {
        return Err(Problems(problems));
    }
    let mut services: Vec<ServiceEntry> = d
        .services
        .iter()
        .filter(|s| s.host.as_deref() == Some(host))
        .cloned()
        .map(|mut s| {
            s.host = None;
            s
        })
        .collect();
    if !routes.is_empty() {
        services.push(bridge_entry(d, h, &routes, base));
    }
    Ok(Descriptor {
        prefix: host_prefix(d, h),
        services,
        hosts: Vec::new(),
        link: Default::default(),
        ..d.clone()
    })
}

#[cfg(test)]
#[path = "partition_tests.rs"]
mod tests;
