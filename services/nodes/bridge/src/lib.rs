//! The host bridge of a partitioned deployment (issue 7): each host of a
//! suite split over several computers runs its services on its own
//! iceoryx2 prefix, and one `spacepose-bridge` forwards the topics that
//! cross hosts over zenoh, in the suite's postcard codec (size and schema
//! checks on every payload, clouds included).
//!
//! - Keys: `spacepose/{suite_prefix}/link/{topic}`, shared by every host
//!   (the iceoryx2 prefixes differ, the suite prefix does not). They are
//!   not the ground's keys (`.../wire/command`, `.../telemetry/**`), so a
//!   command the telemetry service injected on the ground host and that
//!   this bridge forwards never comes back to the telemetry's own route.
//! - Routes: each topic goes one way on a host (`to-zenoh` where it is
//!   produced for other hosts, `from-zenoh` where it is consumed and
//!   produced elsewhere); `spacepose up --host` derives them from the
//!   descriptor (`spacepose::suite::partition`).
//! - Access: a host that listens requires a `peers` account of the link
//!   dictionary from every host that connects (usrpwd) and enforces an ACL
//!   by user name (default deny); a host that connects presents its account
//!   (`credentials_file`). See `docs/security.md`.
//!
//! The library holds the configuration and its checks, the link the node
//! asks the runtime for ([`link_spec`]: session, access, account, routes,
//! the wait for the consuming hosts), and [`BridgeNode`], which turns the
//! routes' figures into health counters and state and writes the
//! statistics file ([`stats`]). The runtime's link does the forwarding.
#![forbid(unsafe_code)]

pub mod config;
pub mod error;
pub mod link;
pub mod node;
pub mod stats;

pub use config::{
    BridgeNodeConfig, BridgeServiceConfig, LinkAccess, LinkEndpoints, RouteConfig, RouteDirection,
    link_key,
};
pub use error::BridgeError;
pub use link::link_spec;
pub use node::BridgeNode;
