//! The `spacepose-telemetry` service: the suite seen from the ground.
//!
//! [`TelemetryNode`] turns the suite's wire messages (pose estimates,
//! filter states, health and, from simulated sources, truth) into the
//! ground-facing JSON of [`spacepose_messages::telemetry`] under
//! `spacepose/{prefix}/telemetry/`, rate-limited per key; matches estimates
//! with simulator truth by frame sequence to compute the errors (angle `d`
//! of seed 004 Eq. 12 and position distance); and keeps the latest state,
//! which the queryable `latest` answers with. The node never touches the
//! bus or zenoh: it asks the runtime for its ground link ([`link_spec`]).
//!
//! Keys (below `spacepose/{prefix}/telemetry/`): `pose`, `filter`,
//! `health/<instance>`, `truth`, `errors`, and the queryable `latest`. The
//! schema is documented in `docs/telemetry.md` and on the types.
//!
//! The link also carries the ground -> suite command path: a route forwards
//! postcard `Command`s from `spacepose/{prefix}/wire/command` to the bus;
//! payloads the codec refuses are counted in this service's `rejected_wire`
//! health counter ([`CommandRoute`]).
//!
//! Security: with an `[access]` table the zenoh session requires a usrpwd
//! account from every connecting peer and enforces an ACL by username
//! (readers: telemetry only; operators: telemetry and commands; default
//! deny), so only operators' commands ever reach the route. Without it,
//! anyone who reaches the endpoints may command the suite: the endpoints are
//! loopback by default, and listening elsewhere without `[access]` is
//! warned about. Why usernames (not TLS certificates, interfaces or zenoh
//! ids): `spacepose_bus::zenoh_access` and `docs/security.md`.
#![forbid(unsafe_code)]

pub mod commands;
pub mod config;
pub mod error;
pub mod hub;
pub mod latest;
pub mod link;
pub mod node;
pub mod rate;

pub use commands::CommandRoute;
pub use config::{AccessConfig, Rates, TelemetryConfig, TelemetryNodeConfig, ZenohEndpoints};
pub use error::TelemetryError;
pub use hub::{Output, TelemetryHub};
pub use latest::{FrameStats, LATEST_KEY, TelemetryLatest};
pub use link::link_spec;
pub use node::TelemetryNode;
pub use rate::RateLimiter;
