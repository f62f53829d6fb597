//! `spacepose up`: validate a descriptor, start its services, wait for their
//! heartbeats, leave them running.

use super::binaries::BinarySearch;
use super::descriptor::Descriptor;
use super::health::HealthWatch;
use super::launch::{RunningSuite, start};
use super::plan::{ConfigCheck, Plan, plan};
use anyhow::{Context, Result};
use spacepose_bus::Bus;
use std::io::Write;
use std::path::Path;

/// Command-line overrides of a descriptor.
#[derive(Debug, Clone, Default)]
pub struct Overrides {
    /// Deployment prefix.
    pub prefix: Option<String>,
    /// zenoh endpoints to listen on (replace the descriptor's).
    pub listen: Option<Vec<String>>,
    /// zenoh endpoints to connect to (replace the descriptor's).
    pub connect: Option<Vec<String>>,
}

impl Overrides {
    /// Applies the overrides to `d`.
    pub fn apply(&self, d: &mut Descriptor) {
        if let Some(p) = &self.prefix {
            d.prefix.clone_from(p);
        }
        if let Some(l) = &self.listen {
            d.zenoh.listen.clone_from(l);
        }
        if let Some(c) = &self.connect {
            d.zenoh.connect.clone_from(c);
        }
    }
}

/// Loads, overrides and validates a descriptor file.
pub fn load_plan(path: &Path, overrides: &Overrides) -> Result<(Descriptor, Plan)> {
    let mut d = Descriptor::load(path)?;
    overrides.apply(&mut d);
    let p = plan_descriptor(&d, path)?;
    Ok((d, p))
}

/// Validates an (already overridden) descriptor read from `path`.
pub fn plan_descriptor(d: &Descriptor, path: &Path) -> Result<Plan> {
    let base = path.parent().unwrap_or(Path::new("."));
    let search = BinarySearch::from_env(base);
    plan(d, &search, ConfigCheck::Run)
        .with_context(|| format!("{} was not started", path.display()))
}

/// Opens this process's bus node for a plan and starts the suite.
pub fn bring_up(
    plan: &Plan,
    role: &str,
    out: &mut dyn Write,
) -> Result<(Bus, HealthWatch, RunningSuite)> {
    let bus = Bus::open(
        &plan.names,
        &format!("spacepose-{role}-{}", std::process::id()),
    )
    .context("opening the iceoryx2 node")?;
    let mut watch = HealthWatch::new(&bus, &plan.names)?;
    let suite = start(plan, &mut watch, out)?;
    Ok((bus, watch, suite))
}

/// `spacepose up <descriptor>`.
pub fn run(path: &Path, overrides: &Overrides, out: &mut dyn Write) -> Result<()> {
    let (_, plan) = load_plan(path, overrides)?;
    let (bus, watch, suite) = bring_up(&plan, "up", out)?;
    drop(watch);
    drop(bus);
    let state = suite.detach();
    writeln!(
        out,
        "deployment {:?} is up ({} instances); logs in {}; stop it with `spacepose down --prefix {}`",
        state.prefix,
        state.instances.len(),
        super::state::run_dir(&state.prefix).display(),
        state.prefix
    )?;
    Ok(())
}
