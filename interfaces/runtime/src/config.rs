//! Service configuration files (TOML).

use anyhow::{Context, bail};
use serde::de::DeserializeOwned;
use std::path::Path;

/// A service's configuration: TOML with `#[serde(deny_unknown_fields)]` on
/// the struct, defaults for absent fields, and a validation step.
pub trait ServiceConfig: DeserializeOwned + Default {
    /// Rejects NaN and out-of-range values, with a message naming the field.
    fn validate(&self) -> Result<(), String>;

    /// The instance name the file sets, if any (`--instance` wins over it).
    fn instance(&self) -> Option<&str> {
        None
    }
}

/// Loads and validates the configuration at `path` (defaults when `None`).
///
/// When the process was started with `--check` ([`crate::ServiceArgs::check`]),
/// a valid configuration prints `configuration ok` and ends the process with
/// status 0 here, before the service opens the bus; an invalid one is
/// returned as the error, as without `--check`.
///
/// # Errors
/// The file cannot be read, is not valid TOML for `C` (unknown keys
/// included), or fails [`ServiceConfig::validate`]; the message names the file.
pub fn load_config<C: ServiceConfig>(path: Option<&Path>) -> anyhow::Result<C> {
    let config = read_config(path)?;
    if check_requested(std::env::args_os()) {
        println!("configuration ok");
        std::process::exit(0);
    }
    Ok(config)
}

/// True when the command line holds `--check`. The flag is declared in
/// [`crate::ServiceArgs`], so clap has already refused malformed command lines.
fn check_requested(mut args: impl Iterator<Item = std::ffi::OsString>) -> bool {
    args.next();
    args.any(|a| a == "--check")
}

fn read_config<C: ServiceConfig>(path: Option<&Path>) -> anyhow::Result<C> {
    let Some(path) = path else {
        let config = C::default();
        if let Err(e) = config.validate() {
            bail!("the default configuration is invalid: {e}");
        }
        return Ok(config);
    };
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read config file {}", path.display()))?;
    let config: C =
        toml::from_str(&text).with_context(|| format!("invalid config file {}", path.display()))?;
    if let Err(e) = config.validate() {
        bail!("invalid config file {}: {e}", path.display());
    }
    Ok(config)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[derive(Debug, Deserialize, PartialEq)]
    #[serde(deny_unknown_fields, default)]
    struct Demo {
        rate_hz: f64,
        name: String,
    }

    impl Default for Demo {
        fn default() -> Self {
            Demo {
                rate_hz: 1.0,
                name: "a".into(),
            }
        }
    }

    impl ServiceConfig for Demo {
        fn validate(&self) -> Result<(), String> {
            if self.rate_hz.is_finite() && self.rate_hz >= 0.0 {
                Ok(())
            } else {
                Err(format!(
                    "rate_hz must be finite and >= 0, got {}",
                    self.rate_hz
                ))
            }
        }
    }

    #[test]
    fn check_is_requested_by_the_flag_only() {
        let args = |v: &[&str]| v.iter().map(std::ffi::OsString::from).collect::<Vec<_>>();
        assert!(check_requested(
            args(&["svc", "--config", "c.toml", "--check"]).into_iter()
        ));
        assert!(!check_requested(
            args(&["svc", "--config", "c.toml"]).into_iter()
        ));
        assert!(!check_requested(args(&["--check"]).into_iter()));
    }

    #[test]
    fn files_load_with_defaults_and_errors_name_the_file() {
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(load_config::<Demo>(None).unwrap(), Demo::default());
        let ok = dir.path().join("ok.toml");
        std::fs::write(&ok, "rate_hz = 5.0\n").unwrap();
        let c: Demo = load_config(Some(&ok)).unwrap();
        assert_eq!((c.rate_hz, c.name.as_str()), (5.0, "a"));
        for (file, text) in [
            ("unknown.toml", "rate = 5.0\n"),
            ("nan.toml", "rate_hz = nan\n"),
            ("syntax.toml", "rate_hz = \n"),
        ] {
            let p = dir.path().join(file);
            std::fs::write(&p, text).unwrap();
            let e = format!("{:#}", load_config::<Demo>(Some(&p)).unwrap_err());
            assert!(e.contains(file), "{e}");
        }
        let e = format!(
            "{:#}",
            load_config::<Demo>(Some(&dir.path().join("absent.toml"))).unwrap_err()
        );
        assert!(e.contains("absent.toml"), "{e}");
    }
}
