//! Health and heartbeat of every service.

use crate::codec::{CodecError, WireMessage, check_code, check_name, fixed_max_wire_bytes};
use crate::error::MessageError;
use crate::{Name, SCHEMA_VERSION};
use iceoryx2::prelude::ZeroCopySend;
use serde::{Deserialize, Serialize};

/// Life-cycle state of a service (stored as `u8` in [`Health::state`]).
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ServiceState {
    /// Started, not yet processing.
    Starting = 0,
    /// Processing normally.
    Running = 1,
    /// Processing, but with errors or a lost track.
    Degraded = 2,
    /// Shutting down.
    Stopping = 3,
}

impl ServiceState {
    /// Decodes the `u8` code.
    pub fn from_u8(code: u8) -> Result<ServiceState, MessageError> {
        match code {
            0 => Ok(ServiceState::Starting),
            1 => Ok(ServiceState::Running),
            2 => Ok(ServiceState::Degraded),
            3 => Ok(ServiceState::Stopping),
            _ => Err(MessageError::UnknownCode {
                what: "service state",
                code,
            }),
        }
    }

    /// Lower-case name (`"starting"`, `"running"`, `"degraded"`, `"stopping"`).
    pub fn as_str(self) -> &'static str {
        match self {
            ServiceState::Starting => "starting",
            ServiceState::Running => "running",
            ServiceState::Degraded => "degraded",
            ServiceState::Stopping => "stopping",
        }
    }
}

/// Counters of one service since it started (frames unless said
/// otherwise): the one declaration, carried in [`Health`], kept by the
/// runtime and shown in telemetry.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ZeroCopySend, Serialize, Deserialize)]
#[type_name("spacepose::Counters")]
pub struct Counters {
    /// Frames (or messages) received.
    pub frames_in: u64,
    /// Frames (or messages) published.
    pub frames_out: u64,
    /// Frames that held NaN or infinite points.
    pub rejected_non_finite: u64,
    /// Empty frames rejected.
    pub rejected_empty: u64,
    /// Frames above capacity rejected.
    pub rejected_oversized: u64,
    /// Wire payloads rejected by the codec (garbage on a zenoh key, a
    /// message a service refused).
    pub rejected_wire: u64,
    /// Other errors (processing, bus, files).
    pub errors: u64,
    /// Sequence of the last frame processed.
    pub last_frame: u64,
    /// Frames whose per-point times were derived over the scan interval
    /// because the recording has no time field (a replay source; the
    /// tracker's motion compensation then rests on an assumption). Absent
    /// from older telemetry JSON: read as 0 there (postcard always carries it).
    #[serde(default)]
    pub derived_times: u64,
}

impl Counters {
    /// Frames (or payloads) rejected for any reason: non-finite points,
    /// empty, oversized, refused by the codec.
    pub fn rejected(&self) -> u64 {
        self.rejected_non_finite
            + self.rejected_empty
            + self.rejected_oversized
            + self.rejected_wire
    }
}

/// Heartbeat and counters of one service instance.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, Serialize, Deserialize)]
#[type_name("spacepose::Health")]
pub struct Health {
    /// Schema version of the sender ([`SCHEMA_VERSION`]).
    pub schema: u16,
    /// [`ServiceState`] code.
    pub state: u8,
    /// Process id of the service.
    pub pid: u32,
    /// Instance name (e.g. `"tracker-a"`).
    pub instance: Name,
    /// Service kind (e.g. `"tracker"`).
    pub service: Name,
    /// Heartbeat counter (starts at 0).
    pub sequence: u64,
    /// Time since the service started (s).
    pub uptime_s: f64,
    /// What the service counted since it started.
    pub counters: Counters,
    /// CLOCK_REALTIME at send (ns since the Unix epoch).
    pub published_ns: i64,
}

impl Health {
    /// A fresh heartbeat for `service`/`instance` of process `pid`, state starting.
    pub fn new(service: Name, instance: Name, pid: u32) -> Self {
        Self {
            schema: SCHEMA_VERSION,
            state: ServiceState::Starting as u8,
            pid,
            instance,
            service,
            ..Self::default()
        }
    }
}

impl WireMessage for Health {
    const KIND: u8 = 6;
    const MAX_WIRE_BYTES: usize = fixed_max_wire_bytes::<Self>();

    fn schema(&self) -> u16 {
        self.schema
    }

    fn validate(&self) -> Result<(), CodecError> {
        check_code("state", self.state, ServiceState::Stopping as u8)?;
        check_name("instance", &self.instance)?;
        check_name("service", &self.service)
    }

    fn set_published_ns(&mut self, ns: i64) {
        self.published_ns = ns;
    }
}
