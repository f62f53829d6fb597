//! `spacepose down`: stop a deployment and clean up after it.

use super::process::{STOP_GRACE, terminate};
use super::state::RunState;
use anyhow::{Context, Result};
use spacepose_bus::{cleanup_dead_nodes, iceoryx2_config};
use spacepose_messages::Names;
use std::io::Write;
use std::path::Path;

/// Stops the deployment `prefix` (the only one running when `None`): its
/// supervisor first (which stops the services), then whatever is left; returns
/// once every process has exited.
pub fn run(prefix: Option<&str>, out: &mut dyn Write) -> Result<()> {
    let state = RunState::select(prefix)?;
    if let Some(pid) = state.supervisor_pid.filter(|p| *p != std::process::id()) {
        let exe = std::env::current_exe()?;
        // The supervisor stops the services itself; it gets their grace
        // period plus its own.
        let killed = terminate(
            &[("supervisor", pid, exe.as_path())],
            STOP_GRACE + std::time::Duration::from_secs(3),
            || {},
        );
        if !killed.is_empty() {
            writeln!(out, "the supervisor (pid {pid}) had to be killed")?;
        }
    }
    let procs: Vec<(&str, u32, &Path)> = state
        .instances
        .iter()
        .map(|i| (i.name.as_str(), i.pid, i.binary.as_path()))
        .collect();
    let killed = terminate(&procs, STOP_GRACE, || {});
    writeln!(
        out,
        "stopped {} instance(s) of {:?}",
        procs.len(),
        state.prefix
    )?;
    if !killed.is_empty() {
        writeln!(
            out,
            "killed after {} s: {}",
            STOP_GRACE.as_secs(),
            killed.join(", ")
        )?;
    }
    let left: Vec<&str> = procs
        .iter()
        .filter(|(_, pid, b)| super::process::is_alive(*pid, b))
        .map(|(n, _, _)| *n)
        .collect();
    if !left.is_empty() {
        anyhow::bail!("still running after SIGKILL: {}", left.join(", "));
    }
    cleanup(&state.prefix, out)
}

/// Removes the state file of `prefix`, the resources of its dead iceoryx2
/// nodes, and, once no node of the prefix is left, its shared-memory files.
pub fn cleanup(prefix: &str, out: &mut dyn Write) -> Result<()> {
    let _ = std::fs::remove_file(RunState::path(prefix));
    let names = Names::new(prefix)?;
    let config = iceoryx2_config(&names)?;
    let cleaned = cleanup_dead_nodes(&config).context("cleaning dead iceoryx2 nodes")?;
    if cleaned > 0 {
        writeln!(
            out,
            "removed the resources of {cleaned} dead iceoryx2 node(s)"
        )?;
    }
    let removed = spacepose_bus::node::remove_deployment_files(&names)?;
    if removed > 0 {
        tracing::info!(removed, "removed shared-memory files of {prefix:?}");
    }
    Ok(())
}
