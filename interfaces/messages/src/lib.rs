//! Message types, service names, the postcard codec and the JSON telemetry
//! schema of the spacepose service suite.
//!
//! Fixed-size messages are `#[repr(C)]` and `ZeroCopySend` with an explicit
//! `type_name` (`"spacepose::X"`), so every binary of the suite agrees on the
//! iceoryx2 type whatever crate path it was built from. Clouds travel on
//! iceoryx2 as `[WirePoint]` with a [`CloudHeader`] user header, and cast to
//! `[spacepose_geometry::Point]` without copying. Everything that crosses
//! zenoh goes through [`codec`] (postcard with a versioned envelope); ground
//! tools read the JSON of [`telemetry`].

pub mod acquisition;
pub mod clock;
pub mod cloud;
pub mod codec;
pub mod command;
pub mod convert;
pub mod error;
pub mod filter;
pub mod graph;
pub mod health;
pub mod message;
pub mod name;
pub mod names;
pub mod pose;
pub mod telemetry;
pub mod truth;

pub use acquisition::{AcquisitionMethod, AcquisitionResult, Verification};
pub use clock::{elapsed_ms, realtime_ns};
pub use cloud::{CloudHeader, CloudMsg, MAX_POINTS, WirePoint, as_points, as_wire};
pub use codec::{WireMessage, decode, encode};
pub use command::{Command, CommandKind};
pub use error::{CodecError, MessageError};
pub use filter::FilterState;
pub use graph::{Need, ServiceKind};
pub use health::{Counters, Health, ServiceState};
pub use message::{Cloud, Message};
pub use name::Name;
pub use names::{Names, Topic};
pub use pose::{PoseEstimate, TrackingMode, WireStatus, mode_from_code};
pub use truth::TruthMsg;

/// Re-export of the derive and trait needed to define further payload types.
pub use iceoryx2::prelude::ZeroCopySend;

/// Version of the wire schema (the codec envelope and every `schema` field).
pub const SCHEMA_VERSION: u16 = 7;
