//! Simulator ground truth (scoring only: telemetry and scorers subscribe).

use crate::SCHEMA_VERSION;
use crate::codec::{WireMessage, fixed_max_wire_bytes};
use iceoryx2::prelude::ZeroCopySend;
use serde::{Deserialize, Serialize};

/// True relative state at the scan end of frame `sequence`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, Serialize, Deserialize)]
#[type_name("spacepose::TruthMsg")]
pub struct TruthMsg {
    /// Schema version of the sender ([`SCHEMA_VERSION`]).
    pub schema: u16,
    /// Sequence of the cloud frame this truth belongs to.
    pub sequence: u64,
    /// Time of validity (s, sensor clock; the scan end).
    pub t_s: f64,
    /// True rotation of `t_sensor_target` as a unit quaternion, order w, x, y, z.
    pub q_sensor_target: [f64; 4],
    /// True position of the target origin in the sensor frame (m).
    pub p_sensor_target: [f64; 3],
    /// True velocity of the target origin relative to the sensor, sensor frame (m/s).
    pub v_sensor: [f64; 3],
    /// True angular velocity of the target relative to the sensor, target body frame (rad/s).
    pub w_target: [f64; 3],
}

impl TruthMsg {
    /// A fresh truth message: schema set, identity rotation.
    pub fn new() -> Self {
        Self {
            schema: SCHEMA_VERSION,
            q_sensor_target: [1.0, 0.0, 0.0, 0.0],
            ..Self::default()
        }
    }
}

impl WireMessage for TruthMsg {
    const KIND: u8 = 5;
    const MAX_WIRE_BYTES: usize = fixed_max_wire_bytes::<Self>();

    fn schema(&self) -> u16 {
        self.schema
    }
}
