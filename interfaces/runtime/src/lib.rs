//! The runtime every spacepose service shares.
//!
//! A service is a bus-free [`Node`] and a `main` that is one call:
//! `spacepose_runtime::main::<MyNode>()`. The runtime parses
//! [`ServiceArgs`], initialises logging, loads and validates the
//! configuration (`--check` stops there), opens the zenoh link the node
//! asks for ([`LinkSpec`]), the bus and a port for every topic the node's
//! kind reads or publishes in the topic graph
//! (`spacepose_messages::ServiceKind`), then loops: wait for an input or
//! the node's next deadline, hand every input to the node, poll it, send
//! the health heartbeat. SIGINT and SIGTERM stop it cleanly.
//!
//! Bad input is the node's to refuse: it logs it, counts it in
//! [`Counters`] and goes on. [`LocalBus`] runs nodes in one thread for
//! unit tests and the evaluation.
#![forbid(unsafe_code)]

pub mod args;
pub mod config;
pub mod health;
pub mod link;
pub mod local;
pub mod node;
mod ports;
pub mod run;
pub mod runtime;
pub mod testing;

pub use args::ServiceArgs;
pub use config::{ServiceConfig, load_config};
pub use health::HealthReporter;
pub use link::{Access, LinkSpec, LinkStatus};
pub use local::{Collect, Envelope, LocalBus};
pub use node::{Ctx, Flow, Node, NodeInfo, Outbox};
pub use run::main;
pub use runtime::{init_logging, shutdown_flag};
pub use spacepose_messages::Counters;
