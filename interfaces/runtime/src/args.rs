//! Command-line arguments every service binary accepts (`spacepose up` passes them).

use clap::Parser;
use std::path::PathBuf;

/// Arguments common to every service binary.
#[derive(Debug, Clone, Parser)]
pub struct ServiceArgs {
    /// TOML file with the service's configuration; absent = defaults.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Deployment prefix: services of other prefixes are never seen.
    #[arg(long, default_value = "spacepose")]
    pub prefix: String,
    /// Instance name (default: the service name, e.g. "tracker").
    #[arg(long)]
    pub instance: Option<String>,
    /// Heartbeat period of the health message (ms).
    #[arg(long, default_value_t = 500)]
    pub heartbeat_ms: u64,
    /// Only check the configuration: [`crate::load_config`] loads and
    /// validates it, prints `configuration ok` and exits with status 0 (or
    /// the service fails with the error) before the bus is touched.
    /// `spacepose up` uses it to validate a descriptor before starting anything.
    #[arg(long)]
    pub check: bool,
}

impl ServiceArgs {
    /// The instance name, `service` when none was given.
    pub fn instance_or(&self, service: &str) -> String {
        self.instance.clone().unwrap_or_else(|| service.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_and_overrides_parse() {
        let a = ServiceArgs::try_parse_from(["x"]).unwrap();
        assert_eq!(a.prefix, "spacepose");
        assert_eq!(a.heartbeat_ms, 500);
        assert!(a.config.is_none());
        assert_eq!(a.instance_or("ingest"), "ingest");
        let a = ServiceArgs::try_parse_from([
            "x",
            "--config",
            "c.toml",
            "--prefix",
            "t1",
            "--instance",
            "ingest-b",
            "--heartbeat-ms",
            "50",
        ])
        .unwrap();
        assert_eq!(a.config.as_deref(), Some(std::path::Path::new("c.toml")));
        assert_eq!((a.prefix.as_str(), a.heartbeat_ms), ("t1", 50));
        assert_eq!(a.instance_or("ingest"), "ingest-b");
        assert!(ServiceArgs::try_parse_from(["x", "--bogus"]).is_err());
        assert!(ServiceArgs::try_parse_from(["x", "--check"]).unwrap().check);
    }
}
