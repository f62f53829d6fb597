//! `spacepose down`: stop a deployment and clean up after it.

use super::launch::STOP_GRACE;
use super::process::terminate;
use super::state::RunState;
use anyhow::{Context, Result};
use iceoryx2::prelude::*;
use spacepose_bus::{cleanup_dead_nodes, iceoryx2_config};
use spacepose_messages::Names;
use std::io::Write;
use std::path::Path;

/// Stops the deployment `prefix` (the only one running when `None`).
pub fn run(prefix: Option<&str>, out: &mut dyn Write) -> Result<()> {
    let state = RunState::select(prefix)?;
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
    let mut alive = 0usize;
    let listed = Node::<ipc::Service>::list(&config, |_| {
        alive += 1;
        CallbackProgression::Continue
    });
    if listed.is_ok() && alive == 0 {
        let removed = remove_shm_files(Path::new("/dev/shm"), &names.iceoryx2_prefix());
        if removed > 0 {
            tracing::info!(removed, "removed shared-memory files of {prefix:?}");
        }
    }
    Ok(())
}

/// True for an iceoryx2 file of exactly this prefix (`{iox_prefix}{40 hex}_…`):
/// prefix `a` must not match the files of prefix `a_b`.
fn is_prefix_file(name: &str, iox_prefix: &str) -> bool {
    name.strip_prefix(iox_prefix).is_some_and(|rest| {
        rest.len() > 41
            && rest.as_bytes()[..40].iter().all(u8::is_ascii_hexdigit)
            && rest.as_bytes()[40] == b'_'
    })
}

fn remove_shm_files(dir: &Path, iox_prefix: &str) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .flatten()
        .filter(|e| {
            e.file_name()
                .to_str()
                .is_some_and(|n| is_prefix_file(n, iox_prefix))
        })
        .filter(|e| std::fs::remove_file(e.path()).is_ok())
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_files_of_the_exact_prefix_match() {
        let hash = "9204dd183d1c4d8e1ff592a30766ffa6765aa8b5";
        assert!(is_prefix_file(
            &format!("sp_a_{hash}_node.0_10_0.global_mgmt"),
            "sp_a_"
        ));
        assert!(!is_prefix_file(
            &format!("sp_a_b_{hash}_node.global_mgmt"),
            "sp_a_"
        ));
        assert!(is_prefix_file(
            &format!("sp_a_b_{hash}_node.global_mgmt"),
            "sp_a_b_"
        ));
        assert!(!is_prefix_file("sp_a_", "sp_a_"));
    }
}
