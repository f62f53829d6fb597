//! Configuration of the telemetry service (TOML; keys in
//! `deploy/examples/telemetry.toml` and `README.md`).

use crate::error::TelemetryError;
use serde::{Deserialize, Serialize};
use spacepose_bus::{AccessControl, ZenohConfig};
use spacepose_runtime::ServiceConfig;
use std::path::PathBuf;

/// How the telemetry process joins zenoh: peer mode, explicit endpoints,
/// multicast scouting off (the bus's `ZenohConfig` is built from this).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ZenohEndpoints {
    /// `"peer"` (default) or `"client"`.
    pub mode: String,
    /// Endpoints to listen on; ground tools connect here. Default
    /// `tcp/127.0.0.1:7447` (loopback only).
    pub listen: Vec<String>,
    /// Endpoints to connect to (e.g. a router or the ground station).
    pub connect: Vec<String>,
}

impl ZenohEndpoints {
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

impl Default for ZenohEndpoints {
    fn default() -> Self {
        Self {
            mode: "peer".into(),
            listen: vec!["tcp/127.0.0.1:7447".into()],
            connect: Vec::new(),
        }
    }
}

/// Largest publication rate per stream (Hz); 0 = every message.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Rates {
    /// `pose` (default 0: every estimate reaches the ground).
    pub pose_hz: f64,
    /// `filter` (default 10 Hz).
    pub filter_hz: f64,
    /// `health/<instance>`, per instance (default 2 Hz).
    pub health_hz: f64,
    /// `truth` (default 0).
    pub truth_hz: f64,
    /// `errors` (default 0).
    pub errors_hz: f64,
}

impl Default for Rates {
    fn default() -> Self {
        Self {
            pose_hz: 0.0,
            filter_hz: 10.0,
            health_hz: 2.0,
            truth_hz: 0.0,
            errors_hz: 0.0,
        }
    }
}

/// Access control of the ground link (`[access]`): usrpwd authentication of
/// every connecting peer and an ACL by username, default deny. The node
/// hands it to the runtime's link as the bus's `AccessControl` (policy and reasons documented
/// there and in `docs/security.md`). Absent = no authentication: keep the
/// default loopback endpoints then.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AccessConfig {
    /// zenoh's usrpwd dictionary, one `user:password` per line (keep it
    /// readable by the service's user only).
    pub dictionary_file: PathBuf,
    /// Accounts allowed to send commands (swap, reinit, mode) and read telemetry.
    pub operators: Vec<String>,
    /// Accounts allowed to read telemetry only.
    #[serde(default)]
    pub readers: Vec<String>,
    /// Accounts of other hosts of the same suite (full access to the
    /// deployment's keys).
    #[serde(default)]
    pub peers: Vec<String>,
}

impl AccessConfig {
    /// The bus's access control of the ground link.
    pub fn access_control(&self) -> AccessControl {
        AccessControl {
            dictionary_file: self.dictionary_file.clone(),
            operators: self.operators.clone(),
            readers: self.readers.clone(),
            peers: self.peers.clone(),
        }
    }
}

/// The telemetry service's TOML file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TelemetryConfig {
    /// zenoh endpoints.
    pub zenoh: ZenohEndpoints,
    /// Stream rate limits.
    pub rates: Rates,
    /// Frames kept to match estimates with truth by sequence.
    pub match_window: usize,
    /// Who may read telemetry and send commands (absent = anyone who
    /// reaches the endpoints).
    pub access: Option<AccessConfig>,
}

impl Default for TelemetryConfig {
    fn default() -> Self {
        Self {
            zenoh: ZenohEndpoints::default(),
            rates: Rates::default(),
            match_window: 64,
            access: None,
        }
    }
}

impl TelemetryConfig {
    /// Checks every value (NaN fails).
    pub fn validate(&self) -> Result<(), TelemetryError> {
        let bad = |m: String| Err(TelemetryError::InvalidConfig(m));
        let r = &self.rates;
        for (name, hz) in [
            ("rates.pose_hz", r.pose_hz),
            ("rates.filter_hz", r.filter_hz),
            ("rates.health_hz", r.health_hz),
            ("rates.truth_hz", r.truth_hz),
            ("rates.errors_hz", r.errors_hz),
        ] {
            if !(hz.is_finite() && hz >= 0.0) {
                return bad(format!("{name} = {hz} must be finite and >= 0"));
            }
        }
        if self.match_window == 0 {
            return bad("match_window must be >= 1".into());
        }
        if self.zenoh.mode != "peer" && self.zenoh.mode != "client" {
            return bad(format!(
                "zenoh.mode = {:?} must be \"peer\" or \"client\"",
                self.zenoh.mode
            ));
        }
        if self.zenoh.listen.is_empty() && self.zenoh.connect.is_empty() {
            return bad("zenoh needs at least one listen or connect endpoint".into());
        }
        if let Some(a) = &self.access
            && a.operators.is_empty()
        {
            return bad("access.operators is empty: nobody could send commands".into());
        }
        Ok(())
    }
}

/// `spacepose-telemetry --config FILE`: a [`TelemetryConfig`] whose
/// validation (also `--check`) reads the accounts' dictionary as well.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(transparent)]
pub struct TelemetryNodeConfig(pub TelemetryConfig);

impl ServiceConfig for TelemetryNodeConfig {
    fn validate(&self) -> Result<(), String> {
        self.0.validate().map_err(|e| e.to_string())?;
        match &self.0.access {
            Some(a) => a.access_control().validate().map_err(|e| e.to_string()),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_loopback_and_strict() {
        let c = TelemetryConfig::default();
        c.validate().unwrap();
        assert_eq!(c.zenoh.listen, ["tcp/127.0.0.1:7447"]);
        let c: TelemetryConfig =
            toml::from_str("[zenoh]\nlisten = [\"tcp/127.0.0.1:9000\"]\n[rates]\npose_hz = 5.0\n")
                .unwrap();
        assert_eq!((c.rates.pose_hz, c.rates.health_hz), (5.0, 2.0));
        assert!(toml::from_str::<TelemetryConfig>("[rates]\nposes_hz = 1.0\n").is_err());
        let mut c = TelemetryConfig::default();
        c.rates.filter_hz = f64::NAN;
        assert!(c.validate().unwrap_err().to_string().contains("filter_hz"));
        let mut c = TelemetryConfig::default();
        c.zenoh.listen.clear();
        assert!(c.validate().is_err());
    }

    #[test]
    fn access_control_is_optional_and_strict() {
        assert_eq!(TelemetryConfig::default().access, None);
        let c: TelemetryConfig = toml::from_str(
            "[access]\ndictionary_file = \"/etc/sp/users\"\noperators = [\"op\"]\nreaders = [\"ground\"]\n",
        )
        .unwrap();
        c.validate().unwrap();
        let a = c.access.unwrap();
        assert_eq!(
            (a.operators, a.readers, a.peers.len()),
            (vec!["op".to_string()], vec!["ground".to_string()], 0)
        );
        let c: TelemetryConfig =
            toml::from_str("[access]\ndictionary_file = \"u\"\noperators = []\n").unwrap();
        assert!(c.validate().unwrap_err().to_string().contains("operators"));
        assert!(
            toml::from_str::<TelemetryConfig>(
                "[access]\ndictionary_file = \"u\"\noperators = []\nwriters = []\n"
            )
            .is_err()
        );
    }

    #[test]
    fn the_node_config_checks_the_dictionary_and_the_example_parses() {
        let dir = tempfile::tempdir().unwrap();
        let users = dir.path().join("users");
        std::fs::write(&users, "op:secret\nground:pw\n").unwrap();
        let file = |operators: &str| {
            format!(
                "[access]\ndictionary_file = {:?}\noperators = [{operators}]\nreaders = [\"ground\"]\n",
                users.display().to_string()
            )
        };
        let c: TelemetryNodeConfig = toml::from_str(&file("\"op\"")).unwrap();
        ServiceConfig::validate(&c).unwrap();
        let c: TelemetryNodeConfig = toml::from_str(&file("\"nobody\"")).unwrap();
        let e = ServiceConfig::validate(&c).unwrap_err();
        assert!(e.contains("nobody") && e.contains("no password"), "{e}");
        std::fs::remove_file(&users).unwrap();
        let c: TelemetryNodeConfig = toml::from_str(&file("\"op\"")).unwrap();
        let e = ServiceConfig::validate(&c).unwrap_err();
        assert!(e.contains("reading the dictionary"), "{e}");
        let mut c = TelemetryNodeConfig::default();
        c.0.match_window = 0;
        assert!(
            ServiceConfig::validate(&c)
                .unwrap_err()
                .contains("match_window")
        );
        let example = include_str!("../../../../deploy/examples/telemetry.toml");
        let c: TelemetryNodeConfig = toml::from_str(example).unwrap();
        ServiceConfig::validate(&c).unwrap();
        assert_eq!(c.0, TelemetryConfig::default());
    }
}
