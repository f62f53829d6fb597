//! Validation of a descriptor into a [`Plan`]: everything is checked before
//! anything starts, and every problem is reported at once.

use super::binaries::BinarySearch;
use super::config_check::check_config;
use super::descriptor::{Descriptor, ZenohEndpoints};
use super::restart::{Policy, RestartSettings};
use spacepose_messages::ServiceKind;
use spacepose_messages::{Name, Names, Topic};
use std::collections::{BTreeSet, HashMap};
use std::path::PathBuf;
use std::time::Duration;

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

/// Every problem of a descriptor, one line each.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problems(pub Vec<String>);

impl std::fmt::Display for Problems {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the deployment descriptor has {} problem(s):",
            self.0.len()
        )?;
        for p in &self.0 {
            write!(f, "\n  - {p}")?;
        }
        Ok(())
    }
}

impl std::error::Error for Problems {}

/// Whether `plan` runs each binary with `--check` on its configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConfigCheck {
    /// Run `binary --config FILE --check` for every instance.
    Run,
    /// Skip (unit tests without binaries).
    Skip,
}

/// True when lidar-sim's config asks for the truth acquisition.
pub fn truth_init(config: &toml::Table) -> bool {
    config
        .get("truth_init")
        .and_then(toml::Value::as_bool)
        .unwrap_or(false)
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

/// Every required input has a producer among the descriptor's services (a
/// host part's bridge produces its inbound routes).
pub(super) fn check_topics(descriptor: &Descriptor, problems: &mut Vec<String>) {
    let mut producers: HashMap<Topic, Vec<&str>> = HashMap::new();
    for s in &descriptor.services {
        let outputs = match s.kind {
            ServiceKind::Bridge => super::partition::bridge_outputs(&s.config),
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

impl Plan {
    /// The instances in start order: consumers first, sources last.
    pub fn start_order(&self) -> (Vec<&PlannedInstance>, Vec<&PlannedInstance>) {
        self.instances.iter().partition(|i| !i.kind.is_source())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn search() -> BinarySearch {
        BinarySearch {
            exe_dir: None,
            path: vec![],
            base_dir: PathBuf::from("/bin"),
        }
    }

    fn descriptor(body: &str) -> Descriptor {
        let mut text = String::from("prefix = \"t\"\n");
        for line in body.lines() {
            let (name, kind) = line.split_once(' ').unwrap();
            text.push_str(&format!(
                "[[service]]\nname = \"{name}\"\nkind = \"{kind}\"\nbinary = \"/bin/sh\"\n"
            ));
            if kind == "lidar-sim" {
                text.push_str("config = { truth_init = true }\n");
            }
        }
        Descriptor::parse(&text).unwrap()
    }

    #[test]
    fn a_full_suite_plans_with_sources_last() {
        let d = descriptor(
            "sim lidar-sim\ningest ingest\ntracker tracker\nfilter filter\ntelemetry telemetry",
        );
        let p = plan(&d, &search(), ConfigCheck::Skip).unwrap();
        let (first, last) = p.start_order();
        assert_eq!(first.len(), 4);
        assert_eq!(last[0].name, "sim");
        let t = p
            .instances
            .iter()
            .find(|i| i.kind == ServiceKind::Telemetry)
            .unwrap();
        assert_eq!(
            t.config["zenoh"]["listen"][0].as_str(),
            Some(super::super::descriptor::DEFAULT_LISTEN)
        );
        // A restarted sensor resumes from its checkpoint in the run dir.
        let sim = last[0].config["checkpoint_file"].as_str().unwrap();
        assert!(sim.ends_with("/sim.sensorstate"), "{sim}");
    }

    #[test]
    fn topic_mismatches_are_named() {
        let e = plan(
            &descriptor("tracker tracker\nfilter filter"),
            &search(),
            ConfigCheck::Skip,
        )
        .unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("\"cloud\"") && text.contains("add one of: ingest"),
            "{text}"
        );
        assert!(text.contains("truth_init"), "{text}");
        let e = plan(&descriptor("ingest ingest"), &search(), ConfigCheck::Skip).unwrap_err();
        assert!(e.to_string().contains("raw_cloud"), "{e}");
    }

    #[test]
    fn duplicate_and_bad_names_and_missing_binaries_are_reported_together() {
        let mut d = descriptor("sim lidar-sim\nsim ingest\nBad_Name filter");
        d.services[2].binary = Some(PathBuf::from("/nonexistent/spacepose-filter"));
        let e = plan(&d, &search(), ConfigCheck::Skip).unwrap_err();
        let text = e.to_string();
        assert!(text.contains("used twice"), "{text}");
        assert!(text.contains("\"Bad_Name\""), "{text}");
        assert!(text.contains("/nonexistent/spacepose-filter"), "{text}");
        assert!(text.contains("\"pose\""), "{text}");
    }

    #[test]
    fn descriptor_level_problems_are_listed_in_order() {
        let d = Descriptor::parse(
            "prefix = \"Bad Prefix\"\nheartbeat_ms = 0\nhealth_timeout_s = -1.0\n\
             hang_timeout_ms = 0\n[restart]\nwindow_s = 0.0\n\
             [[service]]\nname = \"ingest\"\nkind = \"ingest\"\nbinary = \"/bin/sh\"\nhost = \"a\"\n",
        )
        .unwrap();
        let e = plan(&d, &search(), ConfigCheck::Skip).unwrap_err();
        let prefix = Names::new("Bad Prefix").unwrap_err();
        assert_eq!(
            e.0[..6],
            [
                format!("prefix: {prefix}"),
                "service \"ingest\" names a host, but the descriptor has no [[host]] tables"
                    .to_string(),
                "health_timeout_s must be a positive number of seconds, got -1".to_string(),
                "heartbeat_ms must be >= 1".to_string(),
                "hang_timeout_ms must be longer than heartbeat_ms".to_string(),
                "restart.window_s must be a positive number of seconds, got 0".to_string(),
            ]
        );
        // Then the topic check: ingest's raw_cloud has no producer.
        assert_eq!(e.0.len(), 7, "{e}");
        assert!(e.0[6].contains("raw_cloud"), "{e}");
        assert!(
            e.to_string()
                .starts_with("the deployment descriptor has 7 problem(s):")
        );
    }

    #[test]
    fn an_empty_or_partitioned_descriptor_is_refused() {
        let e = plan(
            &Descriptor::parse("prefix = \"t\"\n").unwrap(),
            &search(),
            ConfigCheck::Skip,
        )
        .unwrap_err();
        assert_eq!(e.0, ["no [[service]] entries"]);
        let mut d = descriptor("sim lidar-sim\ningest ingest");
        let hosts =
            Descriptor::parse("prefix = \"t\"\n[[host]]\nname = \"a\"\n[[host]]\nname = \"b\"\n")
                .unwrap()
                .hosts;
        d.hosts = hosts;
        d.services[0].host = Some("a".into());
        let e = plan(&d, &search(), ConfigCheck::Skip).unwrap_err();
        // Only the partition is reported, not the service's host.
        assert_eq!(e.0.len(), 1, "{e}");
        assert!(
            e.0[0].starts_with("the descriptor is partitioned over hosts a, b: ")
                && e.0[0].ends_with("`spacepose up --host NAME`"),
            "{e}"
        );
    }

    #[test]
    fn timeouts_and_restart_policies_come_from_the_descriptor() {
        let mut d = descriptor("sim lidar-sim\ningest ingest");
        d.heartbeat_ms = 200;
        d.health_timeout_s = 2.5;
        d.restart.policy = Policy::Always;
        d.restart.max_restarts = 2;
        d.services[1].restart_policy = Some(Policy::Never);
        let p = plan(&d, &search(), ConfigCheck::Skip).unwrap();
        assert_eq!(p.names.prefix(), "t");
        assert_eq!(p.heartbeat_ms, 200);
        assert_eq!(p.health_timeout, Duration::from_millis(2500));
        // Default: 3 heartbeat periods + 100 ms.
        assert_eq!(p.hang_timeout, Duration::from_millis(700));
        assert_eq!(p.restart, d.restart);
        assert_eq!(p.zenoh, d.zenoh);
        let names: Vec<&str> = p.instances.iter().map(|i| i.name.as_str()).collect();
        assert_eq!(names, ["sim", "ingest"]);
        assert_eq!(p.instances[0].restart_policy, Policy::Always);
        assert_eq!(p.instances[1].restart_policy, Policy::Never);
        assert_eq!(p.instances[1].binary, PathBuf::from("/bin/sh"));
        d.hang_timeout_ms = Some(201);
        let p = plan(&d, &search(), ConfigCheck::Skip).unwrap();
        assert_eq!(p.hang_timeout, Duration::from_millis(201));
    }

    #[test]
    fn config_check_runs_each_binary_only_when_asked() {
        let mut d = descriptor("sim lidar-sim\ningest ingest");
        d.services[0].binary = Some(PathBuf::from("/bin/true"));
        d.services[1].binary = Some(PathBuf::from("/bin/false"));
        let e = plan(&d, &search(), ConfigCheck::Run).unwrap_err();
        assert_eq!(
            e.0,
            [
                "service \"ingest\" (ingest): invalid config: /bin/false --check failed (exit status: 1)"
            ]
        );
        assert!(plan(&d, &search(), ConfigCheck::Skip).is_ok());
        d.services[1].binary = Some(PathBuf::from("/bin/true"));
        assert!(plan(&d, &search(), ConfigCheck::Run).is_ok());
    }
}
