//! zenoh session helper: peer mode, explicit endpoints, loopback by default,
//! multicast scouting off, synchronous API (`zenoh::Wait`).

use crate::error::BusError;
use serde::{Deserialize, Serialize};
use zenoh::Wait;

/// Default zenoh port of a suite.
pub const DEFAULT_ZENOH_PORT: u16 = 7447;

/// How a process joins zenoh.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ZenohConfig {
    /// `"peer"` (default), `"client"` (e.g. a ground tool connecting to a
    /// peer) or `"router"` (the hub of a partitioned suite: it routes
    /// between the hosts connected to it, which peers do not since zenoh 1.9).
    pub mode: String,
    /// Endpoints to listen on, e.g. `"tcp/127.0.0.1:7447"` (loopback by default).
    pub listen: Vec<String>,
    /// Endpoints to connect to (peers need direct links: zenoh ≥ 1.9 does not relay).
    pub connect: Vec<String>,
    /// Multicast scouting (off: no traffic leaves the machine unless asked).
    pub multicast_scouting: bool,
}

impl Default for ZenohConfig {
    fn default() -> Self {
        Self::loopback(DEFAULT_ZENOH_PORT)
    }
}

impl ZenohConfig {
    /// A peer listening on `tcp/127.0.0.1:{port}`, connecting nowhere.
    pub fn loopback(port: u16) -> Self {
        Self {
            mode: "peer".to_string(),
            listen: vec![format!("tcp/127.0.0.1:{port}")],
            connect: Vec::new(),
            multicast_scouting: false,
        }
    }

    /// A client that only connects to `endpoints` (listens nowhere).
    pub fn client(endpoints: &[&str]) -> Self {
        Self {
            mode: "client".to_string(),
            listen: Vec::new(),
            connect: endpoints.iter().map(|e| e.to_string()).collect(),
            multicast_scouting: false,
        }
    }

    /// Adds an endpoint to connect to.
    pub fn connect_to(mut self, endpoint: &str) -> Self {
        self.connect.push(endpoint.to_string());
        self
    }

    /// The zenoh configuration.
    pub fn to_zenoh(&self) -> Result<zenoh::Config, BusError> {
        if !["peer", "client", "router"].contains(&self.mode.as_str()) {
            return Err(BusError::Zenoh(format!(
                "mode {:?} (expected \"peer\", \"client\" or \"router\")",
                self.mode
            )));
        }
        let json = |v: &Vec<String>| serde_json::to_string(v).map_err(BusError::zenoh);
        let mut c = zenoh::Config::default();
        let set = |c: &mut zenoh::Config, key: &str, value: &str| {
            c.insert_json5(key, value)
                .map_err(|e| BusError::Zenoh(format!("{key} = {value}: {e}")))
        };
        set(&mut c, "mode", &format!("{:?}", self.mode))?;
        set(&mut c, "listen/endpoints", &json(&self.listen)?)?;
        set(&mut c, "connect/endpoints", &json(&self.connect)?)?;
        set(
            &mut c,
            "scouting/multicast/enabled",
            if self.multicast_scouting {
                "true"
            } else {
                "false"
            },
        )?;
        Ok(c)
    }
}

/// Opens a zenoh session with `config`.
pub fn open_zenoh(config: &ZenohConfig) -> Result<zenoh::Session, BusError> {
    open_zenoh_with(config, |_| Ok(()))
}

/// Opens a zenoh session with `config`, after `extra` has amended the zenoh
/// configuration (e.g. [`crate::AccessControl::apply`] or
/// [`crate::Credentials::apply`]).
pub fn open_zenoh_with(
    config: &ZenohConfig,
    extra: impl FnOnce(&mut zenoh::Config) -> Result<(), BusError>,
) -> Result<zenoh::Session, BusError> {
    let mut c = config.to_zenoh()?;
    extra(&mut c)?;
    zenoh::open(c)
        .wait()
        .map_err(|e| BusError::Zenoh(format!("opening session: {e}")))
}

/// True for an endpoint on a loopback address (`127.0.0.0/8`, `[::1]`,
/// `localhost`), e.g. `tcp/127.0.0.1:7447`. Anything else, including
/// `0.0.0.0` and `[::]` (every interface), is reachable from the network.
pub fn is_loopback_endpoint(endpoint: &str) -> bool {
    let Some((_, address)) = endpoint.split_once('/') else {
        return false;
    };
    // Drop zenoh endpoint metadata/config (`?...`, `#...`).
    let address = address.split(['?', '#']).next().unwrap_or(address);
    let host = match address.rsplit_once(':') {
        Some((host, _port)) => host,
        None => address,
    };
    let host = host.trim_start_matches('[').trim_end_matches(']');
    if host == "localhost" {
        return true;
    }
    host.parse::<std::net::IpAddr>()
        .is_ok_and(|ip| ip.is_loopback())
}

impl ZenohConfig {
    /// The listen endpoints that are not on a loopback address.
    pub fn non_loopback_listen(&self) -> Vec<&str> {
        self.listen
            .iter()
            .map(String::as_str)
            .filter(|e| !is_loopback_endpoint(e))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_listen_on_loopback_only() {
        assert!(ZenohConfig::default().non_loopback_listen().is_empty());
        assert!(ZenohConfig::loopback(9000).non_loopback_listen().is_empty());
        for e in [
            "tcp/127.0.0.1:7447",
            "tcp/127.3.0.1:1",
            "tcp/[::1]:7447",
            "tcp/localhost:7447",
        ] {
            assert!(is_loopback_endpoint(e), "{e}");
        }
        for e in [
            "tcp/0.0.0.0:7447",
            "tcp/[::]:7447",
            "tcp/10.0.0.2:7447",
            "tcp/ground.example:7447",
            "garbage",
        ] {
            assert!(!is_loopback_endpoint(e), "{e}");
        }
        let mut c = ZenohConfig::default();
        c.listen.push("tcp/0.0.0.0:7448".into());
        assert_eq!(c.non_loopback_listen(), ["tcp/0.0.0.0:7448"]);
        // The zenoh configuration really carries the loopback endpoint.
        let z = ZenohConfig::default().to_zenoh().unwrap();
        assert!(
            z.get_json("listen/endpoints")
                .unwrap()
                .contains("127.0.0.1:7447")
        );
        assert_eq!(z.get_json("scouting/multicast/enabled").unwrap(), "false");
        let mut router = ZenohConfig {
            mode: "router".into(),
            ..ZenohConfig::default()
        };
        assert_eq!(
            router.to_zenoh().unwrap().get_json("mode").unwrap(),
            "\"router\""
        );
        router.mode = "broker".into();
        assert!(router.to_zenoh().is_err());
    }
}
