//! The telemetry service as a library (no bus): turns the suite's wire
//! messages into the ground-facing JSON of
//! [`spacepose_messages::telemetry`], matches estimates with simulator truth
//! by frame sequence to compute the errors (angle `d` of seed 004 Eq. 12 and
//! position distance), keeps the latest state for the zenoh queryable, and
//! rate-limits the streams.
//!
//! Keys (below `spacepose/{prefix}/telemetry/`): `pose`, `filter`,
//! `health/<instance>`, `truth`, `errors`, and the queryable `latest`. The
//! schema is documented in `TELEMETRY.md` and on the types.
#![forbid(unsafe_code)]

pub mod config;
pub mod error;
pub mod hub;
pub mod latest;
pub mod rate;

pub use config::{AccessConfig, Rates, TelemetryConfig, ZenohEndpoints};
pub use error::TelemetryError;
pub use hub::{Output, TelemetryHub};
pub use latest::{FrameStats, LATEST_KEY, TelemetryLatest};
pub use rate::RateLimiter;
