//! Validation of a descriptor into a [`Plan`]: everything is checked before
//! anything starts, and every problem is reported at once.

use super::binaries::BinarySearch;
use super::config_check::check_config;
use super::descriptor::{Descriptor, ZenohEndpoints};
use super::restart::{Policy, RestartSettings};
use super::topics::check_topics;
use spacepose_messages::ServiceKind;
use spacepose_messages::{Name, Names};
use std::collections::BTreeSet;
use std::path::PathBuf;
use std::time::Duration;

pub use super::problems::Problems;
pub use super::topics::truth_init;

/// A validated deployment, ready to start.
#[derive(Debug, Clone)]
pub struct Plan {
    /// Deployment names (prefix).
    pub names: Names,
    /// Heartbeat period of every service (ms).
    pub heartbeat_ms: u64,
    /// How long to wait for every first heartbeat.
    pub health_timeout: Duration,
    /// A service silent for longer than this is hung.
    pub hang_timeout: Duration,
    /// Restart settings of the supervisor.
    pub restart: RestartSettings,
    /// zenoh endpoints of the suite.
    pub zenoh: ZenohEndpoints,
    /// The instances, in descriptor order.
    pub instances: Vec<PlannedInstance>,
}

/// One instance to start.
#[derive(Debug, Clone)]
pub struct PlannedInstance {
    /// Instance name.
    pub name: String,
    /// Service kind.
    pub kind: ServiceKind,
    /// Resolved binary.
    pub binary: PathBuf,
    /// Configuration (with the deployment's zenoh endpoints filled in).
    pub config: toml::Table,
    /// Restart policy.
    pub restart_policy: Policy,
}

/// Whether `plan` runs each binary with `--check` on its configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConfigCheck {
    /// Run `binary --config FILE --check` for every instance.
    Run,
    /// Skip (unit tests without binaries).
    Skip,
}

/// Fills in what the deployment decides for a service: the zenoh endpoints
/// of telemetry (unless its config sets its own `zenoh` table), and the NDT
/// map file of a tracker (unless it sets `map_file`): `map_dir/{name}.ndtmap`,
/// built on the first start and loaded by every restart, so a restarted
/// tracker is back within a fraction of a second instead of rebuilding it;
/// the state snapshot of a filter (`snapshot_file`, `{name}.filterstate`,
/// from which a restarted filter resumes), the checkpoint of a simulated
/// sensor (`checkpoint_file`, `{name}.sensorstate`, from which a restarted
/// lidar-sim continues the scenario at the frame now due) and the
/// statistics file of a bridge (`stats_file`, `{name}.stats.json`), in the
/// same directory.
pub fn deployment_config(
    kind: ServiceKind,
    config: &toml::Table,
    zenoh: &ZenohEndpoints,
    map_dir: &std::path::Path,
    name: &str,
) -> toml::Table {
    let mut config = config.clone();
    if kind == ServiceKind::Tracker && !config.contains_key("map_file") {
        let path = map_dir.join(format!("{name}.ndtmap"));
        config.insert(
            "map_file".into(),
            toml::Value::String(path.display().to_string()),
        );
    }
    let file = |ext: &str| {
        toml::Value::String(map_dir.join(format!("{name}.{ext}")).display().to_string())
    };
    if kind == ServiceKind::Filter && !config.contains_key("snapshot_file") {
        config.insert("snapshot_file".into(), file("filterstate"));
    }
    if kind == ServiceKind::LidarSim && !config.contains_key("checkpoint_file") {
        config.insert("checkpoint_file".into(), file("sensorstate"));
    }
    if kind == ServiceKind::Bridge && !config.contains_key("stats_file") {
        config.insert("stats_file".into(), file("stats.json"));
    }
    if kind == ServiceKind::Telemetry && !config.contains_key("zenoh") {
        let mut z = toml::Table::new();
        let list =
            |v: &[String]| toml::Value::Array(v.iter().cloned().map(toml::Value::String).collect());
        z.insert("listen".into(), list(&zenoh.listen));
        z.insert("connect".into(), list(&zenoh.connect));
        config.insert("zenoh".into(), toml::Value::Table(z));
    }
    config
}

/// Validates `descriptor` into a plan, or lists every problem.
pub fn plan(
    descriptor: &Descriptor,
    search: &BinarySearch,
    check: ConfigCheck,
) -> Result<Plan, Problems> {
    let mut problems = Vec::new();
    let names = Names::new(&descriptor.prefix)
        .map_err(|e| problems.push(format!("prefix: {e}")))
        .ok();
    check_services_and_hosts(descriptor, &mut problems);
    check_timing(descriptor, &mut problems);
    problems.extend(descriptor.restart.problems());
    check_instance_names(descriptor, &mut problems);
    check_topics(descriptor, &mut problems);
    let instances = plan_instances(descriptor, search, check, &mut problems);
    match names {
        Some(names) if problems.is_empty() => Ok(validated_plan(descriptor, names, instances)),
        _ => Err(Problems(problems)),
    }
}

/// The descriptor has services and is not partitioned: a partitioned one is
/// started one host's part at a time (`up --host`), and only its services
/// name a host.
fn check_services_and_hosts(descriptor: &Descriptor, problems: &mut Vec<String>) {
    if descriptor.services.is_empty() {
        problems.push("no [[service]] entries".to_string());
    }
    if !descriptor.hosts.is_empty() {
        let hosts: Vec<&str> = descriptor.hosts.iter().map(|h| h.name.as_str()).collect();
        problems.push(format!(
            "the descriptor is partitioned over hosts {}: start each host's part with `spacepose up --host NAME`",
            hosts.join(", ")
        ));
    } else if let Some(s) = descriptor.services.iter().find(|s| s.host.is_some()) {
        problems.push(format!(
            "service {:?} names a host, but the descriptor has no [[host]] tables",
            s.name
        ));
    }
}

/// The health timeout is a positive duration, the heartbeat period at least
/// 1 ms, and a hang timeout, when given, longer than the heartbeat period.
fn check_timing(descriptor: &Descriptor, problems: &mut Vec<String>) {
    if !(descriptor.health_timeout_s.is_finite() && descriptor.health_timeout_s > 0.0) {
        problems.push(format!(
            "health_timeout_s must be a positive number of seconds, got {}",
            descriptor.health_timeout_s
        ));
    }
    if descriptor.heartbeat_ms == 0 {
        problems.push("heartbeat_ms must be >= 1".to_string());
    }
    if descriptor
        .hang_timeout_ms
        .is_some_and(|h| h <= descriptor.heartbeat_ms)
    {
        problems.push("hang_timeout_ms must be longer than heartbeat_ms".to_string());
    }
}

/// The instances of the descriptor's services whose binary was found, in
/// descriptor order; a missing binary or (with [`ConfigCheck::Run`]) a
/// configuration its binary rejects is a problem.
fn plan_instances(
    descriptor: &Descriptor,
    search: &BinarySearch,
    check: ConfigCheck,
    problems: &mut Vec<String>,
) -> Vec<PlannedInstance> {
    let mut instances = Vec::new();
    for s in &descriptor.services {
        let binary = match search.resolve(s.binary.as_deref(), &s.kind.binary_name()) {
            Ok(b) => b,
            Err(e) => {
                problems.push(format!("service {:?} ({}): {e}", s.name, s.kind));
                continue;
            }
        };
        let map_dir = super::state::run_dir(&descriptor.prefix);
        let config = deployment_config(s.kind, &s.config, &descriptor.zenoh, &map_dir, &s.name);
        if check == ConfigCheck::Run
            && let Err(e) = check_config(&binary, &config)
        {
            problems.push(format!(
                "service {:?} ({}): invalid config: {e}",
                s.name, s.kind
            ));
        }
        instances.push(PlannedInstance {
            name: s.name.clone(),
            kind: s.kind,
            binary,
            config,
            restart_policy: s.restart_policy.unwrap_or(descriptor.restart.policy),
        });
    }
    instances
}

/// The plan of a descriptor without problems; the hang timeout defaults to
/// 3 heartbeat periods + 100 ms.
fn validated_plan(descriptor: &Descriptor, names: Names, instances: Vec<PlannedInstance>) -> Plan {
    Plan {
        names,
        heartbeat_ms: descriptor.heartbeat_ms,
        health_timeout: Duration::from_secs_f64(descriptor.health_timeout_s),
        hang_timeout: Duration::from_millis(
            descriptor
                .hang_timeout_ms
                .unwrap_or(3 * descriptor.heartbeat_ms + 100),
        ),
        restart: descriptor.restart.clone(),
        zenoh: descriptor.zenoh.clone(),
        instances,
    }
}

/// Every instance name is file-safe (it names the run directory's files),
/// a valid bus [`Name`], and used once.
fn check_instance_names(descriptor: &Descriptor, problems: &mut Vec<String>) {
    let mut seen = BTreeSet::new();
    for s in &descriptor.services {
        let file_safe = !s.name.is_empty()
            && s.name
                .bytes()
                .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-' || b == b'_');
        if !file_safe || Name::new(&s.name).is_err() {
            problems.push(format!(
                "service name {:?}: use 1-24 characters of a-z, 0-9, '-' and '_'",
                s.name
            ));
        }
        if !seen.insert(s.name.as_str()) {
            problems.push(format!("service name {:?} is used twice", s.name));
        }
    }
}

/// The filter's configured primary tracker (`primary` in its config).
pub fn configured_primary(plan: &Plan) -> Option<String> {
    plan.instances
        .iter()
        .find(|i| i.kind == ServiceKind::Filter)
        .and_then(|f| f.config.get("primary"))
        .and_then(toml::Value::as_str)
        .map(str::to_string)
}

impl Plan {
    /// The instances in start order: consumers first, sources last.
    pub fn start_order(&self) -> (Vec<&PlannedInstance>, Vec<&PlannedInstance>) {
        self.instances.iter().partition(|i| !i.kind.is_source())
    }
}

#[cfg(test)]
#[path = "plan_tests.rs"]
mod tests;
