//! iceoryx2 and zenoh transport of the spacepose service suite.
//!
//! - [`Bus`]: one iceoryx2 node per process, isolated by the deployment
//!   prefix (`config.global.prefix`), cleaning up dead nodes at start.
//! - [`Publisher`]/[`Subscriber`]: fixed-size messages; [`CloudPublisher`]/
//!   [`CloudSubscriber`]: clouds as `[WirePoint]` slices with a `CloudHeader`,
//!   Static allocation sized to the largest frame. Every publisher notifies an
//!   event service after sending; a [`Waiter`] (iceoryx2 WaitSet) wakes on it.
//! - [`open_zenoh`]: a zenoh session (peer, explicit endpoints, loopback,
//!   no multicast scouting).
//! - [`Bridge`]: allow-listed iceoryx2 <-> zenoh forwarding in the postcard codec.
//! - [`AccessControl`]/[`Credentials`]: usrpwd authentication and an ACL by
//!   username on the ground link (who reads telemetry, who sends commands).
//!
//! zenoh is built with `default-features = false, features = ["transport_tcp",
//! "auth_usrpwd"]` for the whole workspace; liveliness, queryables, the
//! access control and the synchronous API (`zenoh::Wait`) are part of that build.

pub mod bridge;
pub mod cloud;
pub mod error;
pub mod limits;
pub mod node;
pub mod pubsub;
pub mod waiter;
pub mod zenoh_access;
pub mod zenoh_session;

pub use bridge::{Bridge, BridgeStats, Direction, LinkLatency, Route};
pub use cloud::{CloudPublisher, CloudSample, CloudSubscriber};
pub use error::BusError;
pub use node::{Bus, cleanup_dead_nodes, iceoryx2_config};
pub use pubsub::{Msg, Publisher, Subscriber};
pub use waiter::{Waiter, WakeReason, Wakeable};
pub use zenoh_access::{AccessControl, Credentials};
pub use zenoh_session::{
    DEFAULT_ZENOH_PORT, ZenohConfig, is_loopback_endpoint, open_zenoh, open_zenoh_with,
};

/// Re-export of zenoh for services (same version and features as the bus).
pub use zenoh;
