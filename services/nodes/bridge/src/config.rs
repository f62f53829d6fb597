//! Configuration of the bridge service (TOML, written by `spacepose up`;
//! keys in `README.md`).

use crate::error::BridgeError;
use serde::{Deserialize, Serialize};
use spacepose_bus::{AccessControl, Credentials, ZenohConfig};
use spacepose_messages::{Names, Topic};
use spacepose_runtime::ServiceConfig;
use std::path::PathBuf;

/// The zenoh key of `topic` on the link of suite `suite`:
/// `spacepose/{suite}/link/{topic}`.
pub fn link_key(suite: &Names, topic: Topic) -> String {
    suite.zenoh_key(&format!("link/{}", topic.as_str()))
}

/// Which way a topic is forwarded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RouteDirection {
    /// This host's iceoryx2 topic to the link.
    ToZenoh,
    /// The link to this host's iceoryx2 topic.
    FromZenoh,
}

/// One forwarded topic.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RouteConfig {
    /// Topic (`cloud`, `pose`, `filter_state`, `acquisition`, `truth`,
    /// `health`, `command`, `raw_cloud`).
    pub topic: String,
    /// Direction.
    pub direction: RouteDirection,
    /// Largest forwarding rate (Hz); absent = every sample.
    #[serde(default)]
    pub max_rate_hz: Option<f64>,
}

/// How the host joins the link (the bus's `ZenohConfig`; multicast
/// scouting is always off).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LinkEndpoints {
    /// `"peer"`, `"client"` or `"router"` (a hub that routes between the
    /// hosts connected to it; zenoh ≥ 1.9 peers do not relay).
    pub mode: String,
    /// Endpoints to listen on.
    pub listen: Vec<String>,
    /// Endpoints to connect to.
    pub connect: Vec<String>,
}

impl LinkEndpoints {
    /// The bus's session configuration (multicast scouting off).
    pub fn zenoh_config(&self) -> ZenohConfig {
        ZenohConfig {
            mode: self.mode.clone(),
            listen: self.listen.clone(),
            connect: self.connect.clone(),
            multicast_scouting: false,
        }
    }
}

impl Default for LinkEndpoints {
    fn default() -> Self {
        Self {
            mode: "peer".into(),
            listen: Vec::new(),
            connect: Vec::new(),
        }
    }
}

/// Access control of a host that listens on the link.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkAccess {
    /// usrpwd dictionary, `user:password` per line (mode 0600).
    pub dictionary_file: PathBuf,
    /// Accounts of the suite's hosts.
    pub peers: Vec<String>,
}

impl LinkAccess {
    /// The bus's access control of a suite link (peers only).
    pub fn access_control(&self) -> AccessControl {
        AccessControl {
            dictionary_file: self.dictionary_file.clone(),
            operators: Vec::new(),
            readers: Vec::new(),
            peers: self.peers.clone(),
        }
    }
}

/// The bridge service's TOML file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BridgeServiceConfig {
    /// Prefix of the link keys, common to every host of the suite.
    pub suite_prefix: String,
    /// zenoh endpoints of this host.
    pub zenoh: LinkEndpoints,
    /// The forwarded topics.
    pub routes: Vec<RouteConfig>,
    /// Account this host presents to the hosts it connects to (one
    /// `user:password` line).
    pub credentials_file: Option<PathBuf>,
    /// Accounts this host admits when it listens (absent: anyone who
    /// reaches the endpoints; keep them on loopback then).
    pub access: Option<LinkAccess>,
    /// Before its first heartbeat, wait up to this long (s) for a
    /// subscriber on every `to-zenoh` route, i.e. for the hosts that consume
    /// them (0 = do not wait). On the sensor host this keeps the sensor,
    /// started once the bridge is healthy, from publishing into the void.
    pub wait_for_link_s: f64,
    /// JSON file with the bridge's counters and link latencies, rewritten
    /// every `stats_period_s` and at exit (absent = none).
    pub stats_file: Option<PathBuf>,
    /// Period of the statistics (s).
    pub stats_period_s: f64,
}

impl Default for BridgeServiceConfig {
    fn default() -> Self {
        Self {
            suite_prefix: String::new(),
            zenoh: LinkEndpoints::default(),
            routes: Vec::new(),
            credentials_file: None,
            access: None,
            wait_for_link_s: 0.0,
            stats_file: None,
            stats_period_s: 2.0,
        }
    }
}

impl BridgeServiceConfig {
    /// The suite's names (link keys).
    pub fn suite(&self) -> Result<Names, BridgeError> {
        Names::new(&self.suite_prefix)
            .map_err(|e| BridgeError::InvalidConfig(format!("suite_prefix: {e}")))
    }

    /// The routes as (topic, direction, rate), checked.
    pub fn routes(&self) -> Result<Vec<(Topic, RouteDirection, Option<f64>)>, BridgeError> {
        let bad = |m: String| Err(BridgeError::InvalidConfig(m));
        let mut out: Vec<(Topic, RouteDirection, Option<f64>)> = Vec::new();
        for r in &self.routes {
            let Some(topic) = Topic::parse(&r.topic) else {
                return bad(format!("routes: unknown topic {:?}", r.topic));
            };
            if out.iter().any(|(t, _, _)| *t == topic) {
                return bad(format!(
                    "routes: topic {:?} listed twice (a topic crosses a host one way)",
                    r.topic
                ));
            }
            if let Some(hz) = r.max_rate_hz
                && !(hz.is_finite() && hz > 0.0)
            {
                return bad(format!("routes: max_rate_hz of {:?} = {hz}", r.topic));
            }
            out.push((topic, r.direction, r.max_rate_hz));
        }
        Ok(out)
    }

    /// Checks every value (the dictionary and credentials files are read by
    /// [`BridgeNodeConfig`]'s check).
    pub fn validate(&self) -> Result<(), BridgeError> {
        let bad = |m: String| Err(BridgeError::InvalidConfig(m));
        self.suite()?;
        self.routes()?;
        let z = &self.zenoh;
        if !["peer", "client", "router"].contains(&z.mode.as_str()) {
            return bad(format!(
                "zenoh.mode = {:?} must be \"peer\", \"client\" or \"router\"",
                z.mode
            ));
        }
        if z.listen.is_empty() && z.connect.is_empty() {
            return bad("zenoh needs at least one listen or connect endpoint".into());
        }
        if z.mode == "client" && !z.listen.is_empty() {
            return bad("a zenoh client does not listen: remove zenoh.listen".into());
        }
        if self.access.is_some() && !z.listen.is_empty() && !z.connect.is_empty() {
            // usrpwd authenticates the connecting side only: an ACL by user
            // name would deny this host's own outgoing links.
            return bad(
                "with [access], a host either listens (and checks accounts) or connects \
                 (and presents credentials_file), not both"
                    .into(),
            );
        }
        for (name, v) in [
            ("wait_for_link_s", self.wait_for_link_s),
            ("stats_period_s", self.stats_period_s),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(format!("{name} = {v} must be finite and >= 0"));
            }
        }
        if self.stats_period_s == 0.0 {
            return bad("stats_period_s must be > 0".into());
        }
        Ok(())
    }
}

/// `spacepose-bridge --config FILE`: a [`BridgeServiceConfig`] whose
/// validation (also `--check`) reads the link dictionary and the
/// credentials file as well.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(transparent)]
pub struct BridgeNodeConfig(pub BridgeServiceConfig);

impl ServiceConfig for BridgeNodeConfig {
    fn validate(&self) -> Result<(), String> {
        self.0.validate().map_err(|e| e.to_string())?;
        if let Some(a) = &self.0.access {
            a.access_control()
                .validate_link()
                .map_err(|e| e.to_string())?;
        }
        if let Some(path) = &self.0.credentials_file {
            Credentials::from_file(path).map_err(|e| e.to_string())?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HUB: &str = r#"
suite_prefix = "orbit"
wait_for_link_s = 5.0
[zenoh]
mode = "router"
listen = ["tcp/10.0.0.2:7450"]
[access]
dictionary_file = "/etc/spacepose/link-users"
peers = ["host-a", "ground"]
[[routes]]
topic = "cloud"
direction = "from-zenoh"
[[routes]]
topic = "pose"
direction = "to-zenoh"
max_rate_hz = 20.0
"#;

    #[test]
    fn a_hub_configuration_parses_and_checks() {
        let c: BridgeServiceConfig = toml::from_str(HUB).unwrap();
        c.validate().unwrap();
        let routes = c.routes().unwrap();
        assert_eq!(routes[0], (Topic::Cloud, RouteDirection::FromZenoh, None));
        assert_eq!(
            routes[1],
            (Topic::Pose, RouteDirection::ToZenoh, Some(20.0))
        );
        assert_eq!(
            link_key(&c.suite().unwrap(), Topic::FilterState),
            "spacepose/orbit/link/filter_state"
        );
    }

    #[test]
    fn bad_values_are_named() {
        let cases = [
            (HUB.replace("\"pose\"", "\"cloud\""), "twice"),
            (HUB.replace("\"pose\"", "\"poses\""), "poses"),
            (HUB.replace("20.0", "-1.0"), "max_rate_hz"),
            (HUB.replace("\"router\"", "\"broker\""), "zenoh.mode"),
            (HUB.replace("\"router\"", "\"client\""), "does not listen"),
            (HUB.replace("\"orbit\"", "\"Orbit!\""), "suite_prefix"),
            (
                HUB.replace("wait_for_link_s = 5.0", "wait_for_link_s = nan"),
                "wait_for_link_s",
            ),
            (
                HUB.replace("listen = [", "connect = [\"tcp/x:1\"]\nlisten = ["),
                "not both",
            ),
        ];
        for (text, word) in cases {
            let c: BridgeServiceConfig = toml::from_str(&text).unwrap();
            let e = c.validate().unwrap_err().to_string();
            assert!(e.contains(word), "{word}: {e}");
        }
        assert!(toml::from_str::<BridgeServiceConfig>("colour = 1\n").is_err());
        assert!(BridgeServiceConfig::default().validate().is_err());
    }

    #[test]
    fn the_node_config_reads_the_dictionary_and_the_credentials() {
        let dir = tempfile::tempdir().unwrap();
        let users = dir.path().join("link-users");
        std::fs::write(&users, "host-a:pa\nground:pg\n").unwrap();
        let hub = HUB.replace("/etc/spacepose/link-users", &users.display().to_string());
        let c: BridgeNodeConfig = toml::from_str(&hub).unwrap();
        ServiceConfig::validate(&c).unwrap();
        let c: BridgeNodeConfig = toml::from_str(&hub.replace("\"ground\"]", "\"sat\"]")).unwrap();
        let e = ServiceConfig::validate(&c).unwrap_err();
        assert!(e.contains("sat") && e.contains("no password"), "{e}");
        let c: BridgeNodeConfig = toml::from_str(HUB).unwrap();
        let e = ServiceConfig::validate(&c).unwrap_err();
        assert!(e.contains("link-users"), "{e}");
        // A connecting host presents its account; an unreadable one is refused.
        let creds = dir.path().join("host-a.account");
        std::fs::write(&creds, "host-a:pa\n").unwrap();
        let leaf = |path: &std::path::Path| {
            format!(
                "suite_prefix = \"orbit\"\ncredentials_file = {:?}\n[zenoh]\nconnect = [\"tcp/10.0.0.2:7450\"]\n",
                path.display().to_string()
            )
        };
        let c: BridgeNodeConfig = toml::from_str(&leaf(&creds)).unwrap();
        ServiceConfig::validate(&c).unwrap();
        let c: BridgeNodeConfig = toml::from_str(&leaf(&dir.path().join("absent"))).unwrap();
        assert!(ServiceConfig::validate(&c).unwrap_err().contains("absent"));
        // Values are checked first (NaN fails).
        let c: BridgeNodeConfig =
            toml::from_str(&hub.replace("wait_for_link_s = 5.0", "wait_for_link_s = nan")).unwrap();
        assert!(
            ServiceConfig::validate(&c)
                .unwrap_err()
                .contains("wait_for_link_s")
        );
        assert!(ServiceConfig::validate(&BridgeNodeConfig::default()).is_err());
    }
}
