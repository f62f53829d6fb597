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
    /// `"peer"` (default) or `"client"` (e.g. a ground tool connecting to a peer).
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
        if self.mode != "peer" && self.mode != "client" {
            return Err(BusError::Zenoh(format!(
                "mode {:?} (expected \"peer\" or \"client\")",
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
    zenoh::open(config.to_zenoh()?)
        .wait()
        .map_err(|e| BusError::Zenoh(format!("opening session: {e}")))
}
