//! `--record RUN.mcap` and `--view [ADDR]` of `spacepose demo` and
//! `spacepose up`: a recorder instance added to the deployment, writing the
//! run with Foxglove schemas and/or streaming it live to Foxglove.

use super::descriptor::{Descriptor, ServiceEntry};
use anyhow::{Context, Result, bail};
use spacepose_messages::ServiceKind;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};

/// The live view's address of `--view` without a value.
pub const DEFAULT_VIEW: &str = "127.0.0.1:8765";

/// The address of `--view`, checked against the access rule: loopback only
/// (the Foxglove WebSocket protocol has no authentication). Serving beyond
/// this host takes `allow_non_loopback = true` in a recorder's `[live]`
/// table of the descriptor (docs/security.md).
///
/// # Errors
/// A non-loopback address.
pub fn view_addr(addr: SocketAddr) -> Result<SocketAddr> {
    if !addr.ip().is_loopback() {
        bail!(
            "--view {addr}: not a loopback address; the Foxglove WebSocket protocol has no \
             authentication. To serve the run beyond this host, give a recorder service \
             `[live] listen = \"{addr}\"` and `allow_non_loopback = true` in the descriptor"
        );
    }
    Ok(addr)
}

/// Adds the live view on `addr` to `d`: to the first recorder without one
/// (the one `--record` added, when both are given), else as a new recorder
/// instance that writes no file. Nothing changes when a recorder already
/// serves `addr` (the supervisor applies the overrides again).
pub fn add_live_view(d: &mut Descriptor, addr: SocketAddr) {
    let listen = addr.to_string();
    let live_of = |s: &ServiceEntry| {
        s.config
            .get("live")
            .and_then(toml::Value::as_table)
            .cloned()
    };
    let serves = |s: &ServiceEntry| {
        live_of(s).is_some_and(|l| l.get("listen").and_then(toml::Value::as_str) == Some(&listen))
    };
    if d.instances_of(ServiceKind::Recorder).any(serves) {
        return;
    }
    let mut live = toml::Table::new();
    live.insert("listen".into(), toml::Value::String(listen));
    let live = toml::Value::Table(live);
    if let Some(s) = d
        .instances_of_mut(ServiceKind::Recorder)
        .find(|s| !s.config.contains_key("live"))
    {
        s.config.insert("live".into(), live);
        return;
    }
    let mut config = toml::Table::new();
    let (target, scale) = target_of(d);
    config.insert("target".into(), toml::Value::String(target));
    config.insert("target_scale".into(), toml::Value::Float(scale));
    config.insert("live".into(), live);
    push_recorder(d, config);
}

/// The recording's path as the recorder will be given it: absolute (the
/// services do not share the CLI's working directory), ending in `.mcap`,
/// not an existing file, in an existing directory.
///
/// # Errors
/// Any of those rules broken.
pub fn record_path(arg: &Path) -> Result<PathBuf> {
    let path = std::path::absolute(arg)
        .with_context(|| format!("--record {}: no absolute path", arg.display()))?;
    if path.extension().is_none_or(|e| e != "mcap") {
        bail!("--record {}: the file must end in .mcap", arg.display());
    }
    if path.exists() {
        bail!(
            "--record {}: the file exists; remove it or choose another name",
            arg.display()
        );
    }
    if let Some(dir) = path.parent().filter(|d| !d.is_dir()) {
        bail!("--record {}: no directory {}", arg.display(), dir.display());
    }
    Ok(path)
}

/// Adds a recorder instance writing `file` to `d`. Its configuration holds
/// the descriptor as it stands (every other service's configuration
/// included) and the target the trackers use, so the recording shows the
/// model at the estimated pose. Nothing is added when `d` already has a
/// recorder writing `file` (the supervisor applies the overrides again).
pub fn add_recorder(d: &mut Descriptor, file: &Path) {
    let file = file.display().to_string();
    let same_file = |s: &ServiceEntry| {
        s.config.get("file").and_then(toml::Value::as_str) == Some(file.as_str())
    };
    if d.instances_of(ServiceKind::Recorder).any(same_file) {
        return;
    }
    let mut config = toml::Table::new();
    config.insert("file".into(), toml::Value::String(file));
    let (target, scale) = target_of(d);
    config.insert("target".into(), toml::Value::String(target));
    config.insert("target_scale".into(), toml::Value::Float(scale));
    match toml::to_string(d) {
        Ok(text) => {
            config.insert("descriptor".into(), toml::Value::String(text));
        }
        Err(e) => tracing::warn!("the descriptor is not recorded: {e}"),
    }
    push_recorder(d, config);
}

/// Adds a recorder instance with `config`, named `recorder` (or
/// `recorder-2`, ... when taken).
fn push_recorder(d: &mut Descriptor, config: toml::Table) {
    let taken = |n: &str| d.services.iter().any(|s| s.name == n);
    let name = (1u32..)
        .map(|k| match k {
            1 => "recorder".to_string(),
            k => format!("recorder-{k}"),
        })
        .find(|n| !taken(n))
        .unwrap_or_default();
    d.services.push(ServiceEntry {
        name,
        kind: ServiceKind::Recorder,
        binary: None,
        host: None,
        restart_policy: None,
        config,
    });
}

/// The target (and mesh scale) of the first tracker, else of the sensor,
/// else the trackers' default.
fn target_of(d: &Descriptor) -> (String, f64) {
    let from = |kind: ServiceKind, scale_key: &str| {
        d.instances_of(kind).find_map(|s| {
            let target = s.config.get("target")?.as_str()?.to_string();
            let scale = s
                .config
                .get(scale_key)
                .and_then(toml::Value::as_float)
                .unwrap_or(1.0);
            Some((target, scale))
        })
    };
    from(ServiceKind::Tracker, "target_scale")
        .or_else(|| from(ServiceKind::LidarSim, "scale"))
        .unwrap_or_else(|| ("deos".to_string(), 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    const DEMO: &str = r#"
prefix = "demo"
[[service]]
name = "lidar-sim"
kind = "lidar-sim"
config = { target = "envisat", scale = 1.0 }
[[service]]
name = "tracker"
kind = "tracker"
config = { target = "/m/x.stl", target_scale = 0.001 }
"#;

    #[test]
    fn the_recorder_records_the_descriptor_and_shows_the_trackers_target() {
        let mut d = Descriptor::parse(DEMO).unwrap();
        let before = toml::to_string(&d).unwrap();
        add_recorder(&mut d, Path::new("/tmp/run.mcap"));
        add_recorder(&mut d, Path::new("/tmp/run.mcap"));
        let recorders: Vec<&ServiceEntry> = d.instances_of(ServiceKind::Recorder).collect();
        assert_eq!(recorders.len(), 1, "added once");
        let c = &recorders[0].config;
        assert_eq!(recorders[0].name, "recorder");
        assert_eq!(c["file"].as_str(), Some("/tmp/run.mcap"));
        assert_eq!(c["target"].as_str(), Some("/m/x.stl"));
        assert_eq!(c["target_scale"].as_float(), Some(0.001));
        assert_eq!(c["descriptor"].as_str(), Some(before.as_str()));
        add_recorder(&mut d, Path::new("/tmp/other.mcap"));
        assert_eq!(d.services.last().unwrap().name, "recorder-2");
    }

    #[test]
    fn the_live_view_extends_the_recording_or_comes_alone() {
        let addr: SocketAddr = DEFAULT_VIEW.parse().unwrap();
        let mut d = Descriptor::parse(DEMO).unwrap();
        add_recorder(&mut d, Path::new("/tmp/run.mcap"));
        add_live_view(&mut d, addr);
        add_live_view(&mut d, addr);
        let recorders: Vec<&ServiceEntry> = d.instances_of(ServiceKind::Recorder).collect();
        assert_eq!(
            recorders.len(),
            1,
            "the recording's recorder serves the view"
        );
        let live = recorders[0].config["live"].as_table().unwrap();
        assert_eq!(live["listen"].as_str(), Some("127.0.0.1:8765"));

        let mut d = Descriptor::parse(DEMO).unwrap();
        add_live_view(&mut d, "[::1]:9000".parse().unwrap());
        let r = d.instances_of(ServiceKind::Recorder).next().unwrap();
        assert!(!r.config.contains_key("file"), "a live view only");
        assert_eq!(r.config["target"].as_str(), Some("/m/x.stl"));
        assert_eq!(r.config["live"]["listen"].as_str(), Some("[::1]:9000"));
        add_live_view(&mut d, addr);
        assert_eq!(d.services.last().unwrap().name, "recorder-2");

        assert!(view_addr(addr).is_ok());
        let e = view_addr("0.0.0.0:8765".parse().unwrap()).unwrap_err();
        assert!(format!("{e}").contains("allow_non_loopback"), "{e}");
    }

    #[test]
    fn record_paths_are_absolute_new_mcap_files() {
        let dir = tempfile::tempdir().unwrap();
        let run = dir.path().join("run.mcap");
        assert_eq!(record_path(&run).unwrap(), run);
        assert!(record_path(Path::new("rel.mcap")).unwrap().is_absolute());
        std::fs::write(&run, b"").unwrap();
        for bad in [run, dir.path().join("x.bag"), dir.path().join("no/x.mcap")] {
            assert!(record_path(&bad).is_err(), "{}", bad.display());
        }
    }
}
