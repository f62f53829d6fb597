//! `spacepose replay RUN.mcap`: the raw clouds of a recorded run fed back
//! into the suite, then the poses compared with the recorded ones.
//!
//! The suite is the recorded descriptor (its `descriptor.toml` attachment,
//! or `--deploy`) with the sensor and recorders replaced by a pcd-replay
//! instance reading the file, under a fresh prefix. Frames go out at the
//! recorded run's wall rate (the simulated sensor's `rate_hz`), else at
//! recorded speed (`--rate-hz` overrides both). The offline, bit-identical
//! path is `spacepose track --input RUN.mcap` (docs/recording.md).

pub mod compare;
pub mod follow;
pub mod recorded;

use super::descriptor::{Descriptor, ServiceEntry};
use super::up::{Overrides, plan_descriptor};
use anyhow::{Context, Result, bail};
use compare::Comparison;
use recorded::RecordedRun;
use spacepose_messages::ServiceKind;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Options of a replay.
#[derive(Debug, Clone)]
pub struct ReplayOptions {
    /// The recording (an MCAP file written by `--record`).
    pub input: PathBuf,
    /// A descriptor to run instead of the recorded one.
    pub deploy: Option<PathBuf>,
    /// Frames per second; unset: the recorded run's.
    pub rate_hz: Option<f64>,
    /// Where to write the comparison as JSON.
    pub json: Option<PathBuf>,
    /// Prefix, zenoh endpoints, recording of the replay, live view.
    pub overrides: Overrides,
    /// How long to wait for missing poses once the last frame is out.
    pub linger: Duration,
}

/// Kinds replaced by the replay: the sensors, and the recorders of the run
/// (a replay records only where `--record` says).
fn replaced(kind: ServiceKind) -> bool {
    kind.is_source() || kind == ServiceKind::Recorder
}

/// The replay's descriptor: `d` with its sources and recorders replaced by
/// a pcd-replay of `input` at `rate_hz` (unset: the removed sensor's rate,
/// else recorded speed), and the overrides applied.
///
/// # Errors
/// `d` has no sensor, or `input` has no absolute path.
pub fn replay_descriptor(
    mut d: Descriptor,
    input: &Path,
    rate_hz: Option<f64>,
    overrides: &Overrides,
) -> Result<Descriptor> {
    let sources: Vec<&ServiceEntry> = d.services.iter().filter(|s| s.kind.is_source()).collect();
    if sources.is_empty() {
        bail!("the descriptor has no sensor (lidar-sim or pcd-replay) to replace");
    }
    let recorded_rate = sources
        .iter()
        .find_map(|s| s.config.get("rate_hz").and_then(toml::Value::as_float));
    let rate = rate_hz.or(recorded_rate).unwrap_or(0.0);
    d.services.retain(|s| !replaced(s.kind));
    let input = std::path::absolute(input)
        .with_context(|| format!("{}: no absolute path", input.display()))?;
    let mut config = toml::Table::new();
    config.insert("input".into(), input.display().to_string().into());
    config.insert("rate_hz".into(), rate.into());
    config.insert("exit_at_end".into(), false.into());
    d.services.insert(
        0,
        ServiceEntry {
            name: "replay".into(),
            kind: ServiceKind::PcdReplay,
            binary: None,
            host: None,
            restart_policy: None,
            config,
        },
    );
    let mut overrides = overrides.clone();
    overrides
        .prefix
        .get_or_insert_with(super::demo::fresh_prefix);
    overrides.apply(&mut d);
    Ok(d)
}

/// Replays `opts.input` through the suite and compares; progress and the
/// comparison go to `out`.
///
/// # Errors
/// The recording cannot be read, has no descriptor (and none is given), or
/// the suite fails.
pub fn run(opts: &ReplayOptions, out: &mut dyn Write) -> Result<Comparison> {
    let recorded = RecordedRun::read(&opts.input)?;
    if recorded.raw_sequences.is_empty() {
        bail!(
            "{}: no raw clouds with spacepose headers (/spacepose/raw_cloud): not a \
             spacepose recording; track other recordings with `spacepose track`",
            opts.input.display()
        );
    }
    let (d, base) = match &opts.deploy {
        Some(path) => (Descriptor::load(path)?, path.clone()),
        None => {
            let text = recorded.descriptor.as_deref().with_context(|| {
                format!(
                    "{} holds no descriptor.toml attachment: give the suite with --deploy",
                    opts.input.display()
                )
            })?;
            (Descriptor::parse(text)?, opts.input.clone())
        }
    };
    let d = replay_descriptor(d, &opts.input, opts.rate_hz, &opts.overrides)?;
    let plan = plan_descriptor(&d, &base)?;
    writeln!(
        out,
        "replay {:?}: {} raw clouds and {} poses recorded, {} services",
        plan.names.prefix(),
        recorded.raw_sequences.len(),
        recorded.poses.len(),
        plan.instances.len()
    )?;
    let replayed = follow::run(plan, &recorded, opts.linger, out)?;
    let comparison = compare::compare(&recorded, replayed.poses, replayed.acquisitions);
    write!(out, "{}", report(&comparison))?;
    if let Some(path) = &opts.json {
        let json = serde_json::to_string_pretty(&comparison)?;
        std::fs::write(path, json).with_context(|| format!("cannot write {}", path.display()))?;
        writeln!(out, "comparison written to {}", path.display())?;
    }
    Ok(comparison)
}

/// The comparison as text.
pub fn report(c: &Comparison) -> String {
    let mut s = format!(
        "\nposes: {} recorded, {} replayed, {} in both: {} same status, {} identical \
         (status, rotation and position bit for bit)\n",
        c.recorded_poses, c.replayed_poses, c.matched, c.same_status, c.identical
    );
    s += &format!(
        "largest difference: {:.3e} deg, {:.3e} mm; first differing frame: {}\n",
        c.max_angle_deg,
        c.max_position_mm,
        c.first_difference
            .map_or_else(|| "none".to_string(), |k| k.to_string())
    );
    s += &format!(
        "reproduced: {}\n",
        if c.reproduced() { "yes" } else { "no" }
    );
    for r in &c.reasons {
        s += &format!("  why: {r}\n");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sensor_and_recorders_give_way_to_a_replay_at_the_recorded_rate() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../deploy/demo.toml"
        ))
        .unwrap();
        let mut d = Descriptor::parse(&text).unwrap();
        super::super::record::add_recorder(&mut d, Path::new("/tmp/old.mcap"));
        let overrides = Overrides {
            prefix: Some("replaytest".into()),
            ..Overrides::default()
        };
        let r =
            replay_descriptor(d.clone(), Path::new("/data/run.mcap"), None, &overrides).unwrap();
        let kinds: Vec<ServiceKind> = r.services.iter().map(|s| s.kind).collect();
        assert_eq!(kinds[0], ServiceKind::PcdReplay);
        assert!(!kinds.contains(&ServiceKind::LidarSim));
        assert!(!kinds.contains(&ServiceKind::Recorder));
        assert_eq!(kinds.len(), d.services.len() - 1);
        let c = &r.services[0].config;
        assert_eq!(c["input"].as_str(), Some("/data/run.mcap"));
        assert_eq!(
            c["rate_hz"].as_float(),
            Some(5.0),
            "demo.toml's sensor rate"
        );
        assert_eq!(r.prefix, "replaytest");
        let r = replay_descriptor(d.clone(), Path::new("/r.mcap"), Some(2.0), &overrides).unwrap();
        assert_eq!(r.services[0].config["rate_hz"].as_float(), Some(2.0));
        d.services.retain(|s| !s.kind.is_source());
        assert!(replay_descriptor(d, Path::new("/r.mcap"), None, &overrides).is_err());
    }
}
