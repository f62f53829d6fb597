//! The `[live]` table of the recorder's configuration: a Foxglove
//! WebSocket server streaming the recorder's channels, and the suite's
//! access rule for it (loopback unless explicitly allowed;
//! `docs/security.md`).

use serde::{Deserialize, Serialize};
use spacepose_foxglove::LiveOptions;
use std::net::SocketAddr;

/// The default address of the live view (Foxglove's default port).
pub const DEFAULT_LISTEN: &str = "127.0.0.1:8765";

/// Most estimates a trajectory may hold.
const MAX_TRAJECTORY: usize = 10_000;

/// The live view: where it listens and what it sends.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LiveConfig {
    /// Address and port to listen on (an IP address, e.g. `127.0.0.1:8765`
    /// or `[::1]:8765`; port 0: any free port).
    pub listen: String,
    /// Allow an address other than loopback. The Foxglove WebSocket
    /// protocol has no authentication: anyone who reaches the port sees
    /// the run. A warning is logged at start.
    pub allow_non_loopback: bool,
    /// Send the raw cloud of every n-th frame (by sequence); 0: none.
    pub raw_cloud_every: u64,
    /// Send the cropped cloud of every n-th frame; 0: none.
    pub cloud_every: u64,
    /// At most this many points per cloud sent (every k-th point); 0: all.
    pub max_points: usize,
    /// Estimates in the trajectory channel; 0: no trajectory.
    pub trajectory: usize,
}

impl Default for LiveConfig {
    fn default() -> Self {
        let options = LiveOptions::default();
        Self {
            listen: DEFAULT_LISTEN.to_string(),
            allow_non_loopback: false,
            raw_cloud_every: options.raw_cloud_every,
            cloud_every: options.cloud_every,
            max_points: options.max_points,
            trajectory: options.trajectory,
        }
    }
}

impl LiveConfig {
    /// The address to listen on.
    ///
    /// # Errors
    /// `listen` is not an IP address with a port.
    pub fn listen_addr(&self) -> Result<SocketAddr, String> {
        self.listen.parse().map_err(|e| {
            format!(
                "listen = {:?} is not an IP address and port ({e})",
                self.listen
            )
        })
    }

    /// Whether the view is reachable from beyond this host.
    pub fn is_non_loopback(&self) -> bool {
        self.listen_addr().is_ok_and(|a| !a.ip().is_loopback())
    }

    /// What to send.
    pub fn options(&self) -> LiveOptions {
        LiveOptions {
            raw_cloud_every: self.raw_cloud_every,
            cloud_every: self.cloud_every,
            max_points: self.max_points,
            trajectory: self.trajectory,
        }
    }

    /// Checks the address against the access rule, and the trajectory length.
    ///
    /// # Errors
    /// The failing key, named.
    pub fn validate(&self) -> Result<(), String> {
        let addr = self.listen_addr()?;
        if !addr.ip().is_loopback() && !self.allow_non_loopback {
            return Err(format!(
                "listen = {:?} is not a loopback address: the Foxglove WebSocket \
                 protocol has no authentication; set allow_non_loopback = true to \
                 serve the run beyond this host",
                self.listen
            ));
        }
        if self.trajectory > MAX_TRAJECTORY {
            return Err(format!(
                "trajectory = {} must be at most {MAX_TRAJECTORY}",
                self.trajectory
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with(listen: &str, allow: bool) -> LiveConfig {
        LiveConfig {
            listen: listen.into(),
            allow_non_loopback: allow,
            ..LiveConfig::default()
        }
    }

    #[test]
    fn loopback_by_default_and_beyond_only_when_allowed() {
        let d = LiveConfig::default();
        assert_eq!(d.validate(), Ok(()));
        assert_eq!(d.listen_addr().unwrap().to_string(), "127.0.0.1:8765");
        assert!(!d.is_non_loopback());
        for ok in ["[::1]:8765", "127.0.0.1:0", "127.0.0.2:9000"] {
            assert_eq!(with(ok, false).validate(), Ok(()), "{ok}");
        }
        for beyond in ["0.0.0.0:8765", "192.168.1.10:8765", "[::]:8765"] {
            let e = with(beyond, false).validate().unwrap_err();
            assert!(e.contains("allow_non_loopback"), "{e}");
            assert_eq!(with(beyond, true).validate(), Ok(()), "{beyond}");
            assert!(with(beyond, true).is_non_loopback());
        }
        for bad in ["localhost:8765", "127.0.0.1", "", "127.0.0.1:99999"] {
            let e = with(bad, true).validate().unwrap_err();
            assert!(e.contains("listen"), "{e}");
        }
        let long = LiveConfig {
            trajectory: 20_000,
            ..LiveConfig::default()
        };
        assert!(long.validate().unwrap_err().contains("trajectory"));
    }

    #[test]
    fn the_options_follow_the_keys() {
        let c: LiveConfig = toml::from_str(
            "cloud_every = 2\nraw_cloud_every = 5\nmax_points = 0\ntrajectory = 3\n",
        )
        .unwrap();
        let o = c.options();
        assert_eq!(
            (o.cloud_every, o.raw_cloud_every, o.max_points, o.trajectory),
            (2, 5, 0, 3)
        );
        assert_eq!(LiveConfig::default().options(), LiveOptions::default());
    }
}
