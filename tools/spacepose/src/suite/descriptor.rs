//! Deployment descriptors (`deploy/*.toml`): which service instances to start
//! under which prefix, with which zenoh endpoints and configurations.
//!
//! ```toml
//! prefix = "demo"
//! [zenoh]
//! listen = ["tcp/127.0.0.1:7447"]
//! [[service]]
//! name = "tracker"
//! kind = "tracker"
//! config = { mode = "deblur" }
//! ```
//! Unknown keys are errors at every level except inside `config`, which the
//! service's own binary checks (`--check`).
//!
//! A partitioned deployment (`deploy/partitioned.toml`) adds `[[host]]`
//! tables, a `host = "..."` on every service and an optional `[link]`;
//! `spacepose up --host NAME` starts one host's part ([`super::partition`]).

use super::restart::{Policy, RestartSettings};
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use spacepose_messages::ServiceKind;
use std::path::{Path, PathBuf};

/// Default zenoh endpoint of a suite (loopback).
pub const DEFAULT_LISTEN: &str = "tcp/127.0.0.1:7447";

/// A deployment descriptor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Descriptor {
    /// Deployment prefix (`[a-z0-9_-]{1,32}`); every service and key carries it.
    pub prefix: String,
    /// Heartbeat period passed to every service (ms).
    #[serde(default = "default_heartbeat_ms")]
    pub heartbeat_ms: u64,
    /// How long `up` waits for every instance's first heartbeat (s).
    #[serde(default = "default_health_timeout_s")]
    pub health_timeout_s: f64,
    /// A service whose last heartbeat is older than this is hung (ms);
    /// default: 3 heartbeat periods + 100 ms.
    #[serde(default)]
    pub hang_timeout_ms: Option<u64>,
    /// Restart policy of the supervisor (`spacepose up`, `spacepose demo`).
    #[serde(default)]
    pub restart: RestartSettings,
    /// zenoh endpoints of the suite (given to the services that use zenoh).
    #[serde(default)]
    pub zenoh: ZenohEndpoints,
    /// The service instances.
    #[serde(default, rename = "service")]
    pub services: Vec<ServiceEntry>,
    /// Hosts of a partitioned deployment (none: everything on one host).
    #[serde(default, rename = "host")]
    pub hosts: Vec<HostEntry>,
    /// The zenoh link between the hosts of a partitioned deployment.
    #[serde(default)]
    pub link: LinkSettings,
}

/// One host of a partitioned deployment: where its bridge joins the link.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HostEntry {
    /// Host name (`[a-z0-9-]`, 1-12 characters), as in the services' `host`.
    pub name: String,
    /// Local deployment prefix of the host's part: its iceoryx2 prefix,
    /// run directory and `--prefix` of `status`/`down`. Default
    /// `{prefix}-{name}`. Give the ground host the suite prefix to keep the
    /// telemetry keys `spacepose/{prefix}/telemetry/...`.
    #[serde(default)]
    pub prefix: Option<String>,
    /// zenoh mode of the host's bridge: `peer`, `client` or `router`
    /// (peers do not relay since zenoh 1.9: one router in the middle, or
    /// every pair of hosts linked directly).
    #[serde(default = "default_mode")]
    pub mode: String,
    /// Endpoints the host's bridge listens on.
    #[serde(default)]
    pub listen: Vec<String>,
    /// Endpoints the host's bridge connects to.
    #[serde(default)]
    pub connect: Vec<String>,
    /// The account (`user:password` file) this host presents to the hosts
    /// it connects to. Relative to the descriptor's directory.
    #[serde(default)]
    pub credentials_file: Option<PathBuf>,
    /// Wait up to this long (s) for the consuming hosts' subscribers before
    /// the host's sources start (e.g. on the sensor host). 0 = no wait.
    #[serde(default)]
    pub wait_for_link_s: f64,
}

fn default_mode() -> String {
    "peer".to_string()
}

/// Access control and tuning of the link between hosts.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LinkSettings {
    /// usrpwd dictionary of the hosts' accounts; hosts that listen admit
    /// only the `peers` accounts (ACL by user name, default deny).
    /// Relative to the descriptor's directory. None: no access control.
    pub dictionary_file: Option<PathBuf>,
    /// The hosts' accounts (the `peers` role of docs/security.md).
    pub peers: Vec<String>,
    /// Largest rate of clouds over the link (Hz); None: every frame.
    pub cloud_rate_hz: Option<f64>,
}

fn default_heartbeat_ms() -> u64 {
    500
}

fn default_health_timeout_s() -> f64 {
    30.0
}

/// zenoh endpoints of a deployment.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ZenohEndpoints {
    /// Endpoints the suite listens on (loopback by default).
    pub listen: Vec<String>,
    /// Endpoints the suite connects to (e.g. a ground station listening).
    pub connect: Vec<String>,
}

impl Default for ZenohEndpoints {
    fn default() -> Self {
        Self {
            listen: vec![DEFAULT_LISTEN.to_string()],
            connect: Vec::new(),
        }
    }
}

/// One service instance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ServiceEntry {
    /// Instance name, unique in the descriptor (e.g. `"tracker-a"`).
    pub name: String,
    /// Service kind.
    pub kind: ServiceKind,
    /// Binary to run; default: `spacepose-{kind}` next to the running
    /// `spacepose` executable, else on `PATH`. Relative paths are relative to
    /// the descriptor's directory.
    #[serde(default)]
    pub binary: Option<PathBuf>,
    /// Host of a partitioned deployment that runs this instance.
    #[serde(default)]
    pub host: Option<String>,
    /// Restart policy of this instance (default: the descriptor's `[restart]`).
    #[serde(default)]
    pub restart_policy: Option<Policy>,
    /// The service's configuration, written to a TOML file and passed with `--config`.
    #[serde(default)]
    pub config: toml::Table,
}

impl Descriptor {
    /// Parses a descriptor (errors carry the TOML line and column).
    pub fn parse(text: &str) -> Result<Descriptor> {
        Ok(toml::from_str(text)?)
    }

    /// Reads and parses a descriptor file.
    pub fn load(path: &Path) -> Result<Descriptor> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read deployment descriptor {}", path.display()))?;
        Descriptor::parse(&text)
            .with_context(|| format!("invalid deployment descriptor {}", path.display()))
    }

    /// The instances of `kind`.
    pub fn instances_of(&self, kind: ServiceKind) -> impl Iterator<Item = &ServiceEntry> {
        self.services.iter().filter(move |s| s.kind == kind)
    }

    /// Mutable instances of `kind` (for command-line overrides).
    pub fn instances_of_mut(
        &mut self,
        kind: ServiceKind,
    ) -> impl Iterator<Item = &mut ServiceEntry> {
        self.services.iter_mut().filter(move |s| s.kind == kind)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const OK: &str = r#"
prefix = "t1"
[[service]]
name = "sim"
kind = "lidar-sim"
config = { truth_init = true, rate_hz = 5.0 }
[[service]]
name = "ingest"
kind = "ingest"
"#;

    #[test]
    fn parses_with_defaults() {
        let d = Descriptor::parse(OK).unwrap();
        assert_eq!(d.prefix, "t1");
        assert_eq!(d.heartbeat_ms, 500);
        assert_eq!(d.zenoh.listen, vec![DEFAULT_LISTEN.to_string()]);
        assert_eq!(d.services.len(), 2);
        assert_eq!(d.services[0].kind, ServiceKind::LidarSim);
        assert_eq!(d.services[0].config["truth_init"].as_bool(), Some(true));
        assert!(d.services[1].config.is_empty());
        assert_eq!(d.instances_of(ServiceKind::Ingest).count(), 1);
    }

    #[test]
    fn unknown_keys_and_kinds_are_named() {
        let e = Descriptor::parse(&OK.replace("prefix", "prefx")).unwrap_err();
        assert!(format!("{e:#}").contains("prefx"), "{e:#}");
        let e = Descriptor::parse(&format!("{OK}colour = 1\n")).unwrap_err();
        assert!(format!("{e:#}").contains("colour"), "{e:#}");
        let e = Descriptor::parse(&OK.replace("\"ingest\"\n", "\"ingets\"\n")).unwrap_err();
        assert!(format!("{e:#}").contains("ingets"), "{e:#}");
        let e = Descriptor::parse(&format!("{OK}[zenoh]\nlisten = []\nport = 1\n")).unwrap_err();
        assert!(format!("{e:#}").contains("port"), "{e:#}");
    }
}
