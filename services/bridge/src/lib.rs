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
//!   this bridge forwards never comes back to the telemetry's own bridge.
//! - Routes: each topic goes one way on a host (`to-zenoh` where it is
//!   produced for other hosts, `from-zenoh` where it is consumed and
//!   produced elsewhere); `spacepose up --host` derives them from the
//!   descriptor (`spacepose::suite::partition`).
//! - Access: a host that listens requires a `peers` account of the link
//!   dictionary from every host that connects (usrpwd) and enforces an ACL
//!   by user name (default deny); a host that connects presents its account
//!   (`credentials_file`). See `deploy/SECURITY.md`.
//!
//! The library holds the configuration and its checks; `src/main.rs` runs
//! the bus's [`Bridge`](../spacepose_bus/struct.Bridge.html).
#![forbid(unsafe_code)]

pub mod config;
pub mod error;

pub use config::{
    BridgeServiceConfig, LinkAccess, LinkEndpoints, RouteConfig, RouteDirection, link_key,
};
pub use error::BridgeError;
