//! The per-process iceoryx2 node: configuration, dead-node cleanup and the
//! service builders shared by publishers and subscribers.

use crate::error::BusError;
use crate::limits::*;
use crate::waiter::{EventFactory, Waiter};
use iceoryx2::node::{NodeView, NodeWaitFailure};
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::publish_subscribe;
use spacepose_messages::{CloudHeader, Name, Names, WirePoint};
use std::fmt::Debug;
use std::time::Duration;

/// One iceoryx2 node per process, isolated by the deployment prefix.
pub struct Bus {
    node: Node<ipc::Service>,
    names: Names,
    cleaned_dead_nodes: usize,
    // Declared after `node`: dropped after it (fields drop in order).
    _last_node_cleanup: LastNodeCleanup,
}

/// Removes the deployment's leftover shared-memory files once the last
/// node of its prefix has closed (see [`remove_deployment_files`]).
struct LastNodeCleanup(Names);

impl Drop for LastNodeCleanup {
    fn drop(&mut self) {
        match remove_deployment_files(&self.0) {
            Ok(0) => {}
            Ok(n) => tracing::debug!(
                prefix = self.0.prefix(),
                files = n,
                "removed the deployment's shared-memory files"
            ),
            Err(e) => tracing::debug!(prefix = self.0.prefix(), "shared-memory cleanup: {e}"),
        }
    }
}

/// Where iceoryx2 keeps its shared-memory files on Linux.
const SHM_DIR: &str = "/dev/shm";

/// True for an iceoryx2 file of exactly this prefix (`{iox_prefix}{40 hex}_…`):
/// prefix `a` must not match the files of prefix `a_b`.
pub fn is_deployment_file(file_name: &str, iox_prefix: &str) -> bool {
    file_name.strip_prefix(iox_prefix).is_some_and(|rest| {
        rest.len() > 41
            && rest.as_bytes()[..40].iter().all(u8::is_ascii_hexdigit)
            && rest.as_bytes()[40] == b'_'
    })
}

/// Removes the shared-memory files of the deployment `names` when no
/// iceoryx2 node of its prefix is left (alive or dead); returns how many
/// were removed (0 while a node exists).
///
/// iceoryx2 keeps one persistent file per prefix (`…_node.<version>.global_mgmt`,
/// its node counter) after the last node is gone; with a fresh prefix per
/// test or demo run they piled up in `/dev/shm`. Every [`Bus`] calls this
/// when it closes.
pub fn remove_deployment_files(names: &Names) -> Result<usize, BusError> {
    let config = iceoryx2_config(names)?;
    let mut nodes = 0usize;
    Node::<ipc::Service>::list(&config, |_| {
        nodes += 1;
        CallbackProgression::Continue
    })
    .map_err(|e| BusError::Node(format!("listing nodes: {e:?}")))?;
    if nodes > 0 {
        return Ok(0);
    }
    let iox_prefix = names.iceoryx2_prefix();
    let Ok(entries) = std::fs::read_dir(SHM_DIR) else {
        return Ok(0);
    };
    Ok(entries
        .flatten()
        .filter(|e| {
            e.file_name()
                .to_str()
                .is_some_and(|n| is_deployment_file(n, &iox_prefix))
        })
        .filter(|e| std::fs::remove_file(e.path()).is_ok())
        .count())
}

impl std::fmt::Debug for Bus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Bus")
            .field("prefix", &self.names.prefix())
            .field("node", &self.node.name())
            .finish()
    }
}

/// The iceoryx2 configuration of a deployment: defaults (no config file is
/// read) with `global.prefix` = [`Names::iceoryx2_prefix`], so two suites on
/// one machine never share a shared-memory file.
pub fn iceoryx2_config(names: &Names) -> Result<Config, BusError> {
    let mut config = Config::default();
    let prefix = names.iceoryx2_prefix();
    config.global.prefix = FileName::new(prefix.as_bytes()).map_err(|e| BusError::InvalidName {
        name: prefix.clone(),
        reason: format!("{e:?}"),
    })?;
    Ok(config)
}

/// Removes the stale resources of every dead node of this deployment
/// (a process that died without cleaning up). Returns how many were removed.
pub fn cleanup_dead_nodes(config: &Config) -> Result<usize, BusError> {
    let mut dead = Vec::new();
    Node::<ipc::Service>::list(config, |state| {
        if let NodeState::Dead(view) = state {
            dead.push(view);
        }
        CallbackProgression::Continue
    })
    .map_err(|e| BusError::Node(format!("listing nodes: {e:?}")))?;
    let mut cleaned = 0;
    for view in dead {
        let id = format!("{:?}", view.id());
        match view.try_remove_stale_resources() {
            Ok(()) => {
                tracing::info!(node = %id, "removed stale resources of a dead iceoryx2 node");
                cleaned += 1;
            }
            Err(e) => tracing::warn!(node = %id, error = ?e, "could not clean up a dead node"),
        }
    }
    Ok(cleaned)
}

fn service_name(service: &str) -> Result<ServiceName, BusError> {
    ServiceName::new(service).map_err(|e| BusError::InvalidName {
        name: service.to_string(),
        reason: format!("{e:?}"),
    })
}

impl Bus {
    /// Opens this process's node `node_name` (an instance name: 1 to 24
    /// characters of `[A-Za-z0-9_.-]`) in the deployment of `names`, after
    /// removing the resources of dead nodes of the same deployment.
    pub fn open(names: &Names, node_name: &str) -> Result<Bus, BusError> {
        Name::new(node_name).map_err(|e| BusError::InvalidName {
            name: node_name.to_string(),
            reason: e.to_string(),
        })?;
        let config = iceoryx2_config(names)?;
        let cleaned_dead_nodes = cleanup_dead_nodes(&config)?;
        let name = NodeName::new(node_name).map_err(|e| BusError::InvalidName {
            name: node_name.to_string(),
            reason: format!("{e:?}"),
        })?;
        let node = NodeBuilder::new()
            .name(&name)
            .config(&config)
            .create::<ipc::Service>()
            .map_err(|e| BusError::Node(format!("creating node {node_name:?}: {e:?}")))?;
        Ok(Bus {
            node,
            names: names.clone(),
            cleaned_dead_nodes,
            _last_node_cleanup: LastNodeCleanup(names.clone()),
        })
    }

    /// The deployment names.
    pub fn names(&self) -> &Names {
        &self.names
    }

    /// How many dead nodes [`Bus::open`] cleaned up.
    pub fn cleaned_dead_nodes(&self) -> usize {
        self.cleaned_dead_nodes
    }

    /// A waiter with termination handling: once it has waited, SIGINT and
    /// SIGTERM are caught by iceoryx2 and reported as
    /// [`crate::WakeReason::TerminationRequested`].
    pub fn waitset(&self) -> Result<Waiter, BusError> {
        Waiter::new(SignalHandlingMode::HandleTerminationRequests)
    }

    /// A waiter that leaves signals alone (for helper threads, so they do not
    /// consume the main loop's termination request).
    pub fn waitset_without_signals(&self) -> Result<Waiter, BusError> {
        Waiter::new(SignalHandlingMode::Disabled)
    }

    /// Sleeps `cycle` for loops that are driven by time rather than by
    /// messages (e.g. a sensor at 10 Hz). Returns `false` when SIGINT/SIGTERM
    /// arrived (after the first call they are caught, so the loop must stop).
    pub fn sleep(&self, cycle: Duration) -> Result<bool, BusError> {
        match self.node.wait(cycle) {
            Ok(()) => Ok(true),
            Err(NodeWaitFailure::TerminationRequest | NodeWaitFailure::Interrupt) => Ok(false),
        }
    }

    /// The publish-subscribe service of a fixed-size message.
    pub(crate) fn message_service<T: Debug + ZeroCopySend + 'static>(
        &self,
        service: &str,
    ) -> Result<publish_subscribe::PortFactory<ipc::Service, T, ()>, BusError> {
        self.node
            .service_builder(&service_name(service)?)
            .publish_subscribe::<T>()
            .max_publishers(MAX_PUBLISHERS)
            .max_subscribers(MAX_SUBSCRIBERS)
            .max_nodes(MAX_NODES)
            .subscriber_max_buffer_size(MESSAGE_BUFFER)
            .history_size(0)
            .open_or_create()
            .map_err(|e| BusError::service(service, e))
    }

    /// The publish-subscribe service of a cloud (`[WirePoint]` + `CloudHeader`).
    pub(crate) fn cloud_service(
        &self,
        service: &str,
    ) -> Result<publish_subscribe::PortFactory<ipc::Service, [WirePoint], CloudHeader>, BusError>
    {
        self.node
            .service_builder(&service_name(service)?)
            .publish_subscribe::<[WirePoint]>()
            .user_header::<CloudHeader>()
            .max_publishers(CLOUD_MAX_PUBLISHERS)
            .max_subscribers(CLOUD_MAX_SUBSCRIBERS)
            .max_nodes(MAX_NODES)
            .subscriber_max_buffer_size(CLOUD_BUFFER)
            .subscriber_max_borrowed_samples(CLOUD_BORROWED)
            .history_size(0)
            .open_or_create()
            .map_err(|e| BusError::service(service, e))
    }

    /// The event service that wakes the subscribers of `service`.
    pub(crate) fn event_service(&self, service: &str) -> Result<EventFactory, BusError> {
        self.node
            .service_builder(&service_name(service)?)
            .event()
            .max_notifiers(MAX_NOTIFIERS)
            .max_listeners(MAX_LISTENERS)
            .max_nodes(EVENT_MAX_NODES)
            .open_or_create()
            .map_err(|e| BusError::service(service, e))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn files_of(names: &Names) -> Vec<String> {
        std::fs::read_dir(SHM_DIR)
            .unwrap()
            .flatten()
            .filter_map(|e| e.file_name().to_str().map(str::to_string))
            .filter(|n| is_deployment_file(n, &names.iceoryx2_prefix()))
            .collect()
    }

    #[test]
    fn only_files_of_the_exact_prefix_match() {
        let hash = "9204dd183d1c4d8e1ff592a30766ffa6765aa8b5";
        let f = format!("sp_a_{hash}_node.0_10_0.global_mgmt");
        assert!(is_deployment_file(&f, "sp_a_"));
        let g = format!("sp_a_b_{hash}_node.global_mgmt");
        assert!(!is_deployment_file(&g, "sp_a_"));
        assert!(is_deployment_file(&g, "sp_a_b_"));
        assert!(!is_deployment_file("sp_a_", "sp_a_"));
    }

    #[test]
    fn the_last_node_to_close_leaves_no_shared_memory_behind() {
        let prefix = format!("tshm{}", std::process::id());
        let names = Names::new(&prefix).unwrap();
        let a = Bus::open(&names, "a").unwrap();
        let b = Bus::open(&names, "b").unwrap();
        let _sub = a
            .subscriber::<spacepose_messages::Health>(&names.health())
            .unwrap();
        assert!(!files_of(&names).is_empty());
        drop(b);
        // `a` is still open: its files stay.
        assert!(!files_of(&names).is_empty());
        drop(_sub);
        drop(a);
        assert_eq!(files_of(&names), Vec::<String>::new());
    }
}
