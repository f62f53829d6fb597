//! The motion state published by the filter service.

use crate::SCHEMA_VERSION;
use crate::codec::{CodecError, WireMessage, check_code, fixed_max_wire_bytes};
use iceoryx2::prelude::ZeroCopySend;
use serde::{Deserialize, Serialize};

/// State of the relative-motion filter at time `t_s` (seed 000 Eq. 8-11).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, Serialize, Deserialize)]
#[type_name("spacepose::FilterState")]
pub struct FilterState {
    /// Schema version of the sender ([`SCHEMA_VERSION`]).
    pub schema: u16,
    /// 1 when the filter has been initialised, 0 before (the rest is then meaningless).
    pub initialized: u8,
    /// Update counter of the filter (one per fused estimate).
    pub sequence: u64,
    /// Time of validity of the state (s, sensor clock).
    pub t_s: f64,
    /// Rotation of `t_sensor_target` as a unit quaternion, order w, x, y, z.
    pub q_sensor_target: [f64; 4],
    /// Position of the target origin in the sensor frame (m).
    pub p_sensor_target: [f64; 3],
    /// Velocity of the target origin relative to the sensor, in the sensor frame (m/s).
    pub v_sensor: [f64; 3],
    /// Angular velocity of the target relative to the sensor, in the target body frame (rad/s).
    pub w_target: [f64; 3],
    /// Angular velocity of the sensor frame w.r.t. inertial space, in the
    /// sensor frame (rad/s): the chaser's turn as the filter estimates it.
    pub w_inertial_sensor: [f64; 3],
    /// Covariance of the attitude state `[rot (rad); w_target (rad/s);
    /// w_inertial_sensor (rad/s)]`, row major.
    pub attitude_covariance: [[f64; 9]; 9],
    /// Covariance of the position state `[p (m); v (m/s)]`, row major.
    pub position_covariance: [[f64; 6]; 6],
    /// CLOCK_REALTIME at send (ns since the Unix epoch).
    pub published_ns: i64,
}

impl FilterState {
    /// A fresh state: schema set, not initialised, identity rotation.
    pub fn new() -> Self {
        Self {
            schema: SCHEMA_VERSION,
            q_sensor_target: [1.0, 0.0, 0.0, 0.0],
            ..Self::default()
        }
    }
}

impl WireMessage for FilterState {
    const KIND: u8 = 3;
    const MAX_WIRE_BYTES: usize = fixed_max_wire_bytes::<Self>();

    fn schema(&self) -> u16 {
        self.schema
    }

    fn validate(&self) -> Result<(), CodecError> {
        check_code("initialized", self.initialized, 1)
    }

    fn set_published_ns(&mut self, ns: i64) {
        self.published_ns = ns;
    }
}
