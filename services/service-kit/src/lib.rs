//! The common runtime of every spacepose service binary.
//!
//! Every `main.rs`: parse [`ServiceArgs`], [`init_logging`], [`load_config`],
//! `Names::new(&args.prefix)`, `Bus::open`, build its library object, then
//! loop: `waiter.wait(heartbeat)` → drain the subscribers → process →
//! publish → [`HealthReporter::tick`], until [`shutdown_flag`] is set or the
//! waiter reports a termination request. Bad input is logged
//! (`tracing::warn!`), counted in [`Counters`], and the loop goes on.
#![forbid(unsafe_code)]

pub mod args;
pub mod config;
pub mod counters;
pub mod health;
pub mod runtime;
pub mod testing;

pub use args::ServiceArgs;
pub use config::{ServiceConfig, load_config};
pub use counters::Counters;
pub use health::HealthReporter;
pub use runtime::{init_logging, shutdown_flag};
