//! Results of pose acquisition (initialisation of the track).

use crate::codec::{CodecError, WireMessage, check_code, check_name, fixed_max_wire_bytes};
use crate::error::MessageError;
use crate::{Name, SCHEMA_VERSION};
use iceoryx2::prelude::ZeroCopySend;
use serde::{Deserialize, Serialize};

/// How an initial pose was obtained (stored as `u8` in [`AcquisitionResult::method`]).
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum AcquisitionMethod {
    /// Simulator truth (only before the init service exists; documented exception).
    Truth = 0,
    /// Template matching (seed 002).
    TemplateMatching = 1,
    /// CNN pose regression (seed 004).
    Cnn = 2,
    /// A pose the operator gave (`spacepose track --init POSE`).
    Given = 3,
}

impl AcquisitionMethod {
    /// Decodes the `u8` code.
    pub fn from_u8(code: u8) -> Result<AcquisitionMethod, MessageError> {
        match code {
            0 => Ok(AcquisitionMethod::Truth),
            1 => Ok(AcquisitionMethod::TemplateMatching),
            2 => Ok(AcquisitionMethod::Cnn),
            3 => Ok(AcquisitionMethod::Given),
            _ => Err(MessageError::UnknownCode {
                what: "acquisition method",
                code,
            }),
        }
    }

    /// Lower-case name (`"truth"`, `"template-matching"`, `"cnn"`, `"given"`).
    pub fn as_str(self) -> &'static str {
        match self {
            AcquisitionMethod::Truth => "truth",
            AcquisitionMethod::TemplateMatching => "template-matching",
            AcquisitionMethod::Cnn => "cnn",
            AcquisitionMethod::Given => "given",
        }
    }
}

/// Whether the track an acquisition starts awaits its verification by the
/// init service (stored as `u8` in [`AcquisitionResult::verification`];
/// `services/nodes/init/src/verify.rs`, design note
/// `docs/design/acquisition-verification.md`).
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Verification {
    /// Not verified (the truth, a given pose, or init's verification off):
    /// the track it starts is `tracking` at once.
    Trusted = 0,
    /// Init will verify it: the track it starts is published
    /// `unconfirmed` until a record with [`Verification::Confirms`] for
    /// this acquisition's frame follows (or a new acquisition replaces it).
    Pending = 1,
    /// Not an acquisition: confirms the track that the acquisition of
    /// frame `sequence` started (the pose is that acquisition's). Consumers
    /// that start tracks ignore it ([`crate::convert::acquisition_pose`]).
    Confirms = 2,
}

impl Verification {
    /// Decodes the `u8` code.
    pub fn from_u8(code: u8) -> Result<Verification, MessageError> {
        match code {
            0 => Ok(Verification::Trusted),
            1 => Ok(Verification::Pending),
            2 => Ok(Verification::Confirms),
            _ => Err(MessageError::UnknownCode {
                what: "verification",
                code,
            }),
        }
    }

    /// Lower-case name (`"trusted"`, `"pending"`, `"confirms"`).
    pub fn as_str(self) -> &'static str {
        match self {
            Verification::Trusted => "trusted",
            Verification::Pending => "pending",
            Verification::Confirms => "confirms",
        }
    }
}

/// An initial estimate of `t_sensor_target` for the tracker and the filter.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, Serialize, Deserialize)]
#[type_name("spacepose::AcquisitionResult")]
pub struct AcquisitionResult {
    /// Schema version of the sender ([`SCHEMA_VERSION`]).
    pub schema: u16,
    /// [`AcquisitionMethod`] code.
    pub method: u8,
    /// 1 when the acquisition succeeded (the pose is valid), 0 otherwise.
    pub success: u8,
    /// [`Verification`] code: whether the track this starts awaits the
    /// init service's verification, or (`Confirms`) a confirmation of the
    /// track started at `sequence`, not an acquisition.
    pub verification: u8,
    /// Sequence of the cloud frame the pose was computed from.
    pub sequence: u64,
    /// Time of validity of the pose (s, sensor clock).
    pub t_s: f64,
    /// Rotation of `t_sensor_target` as a unit quaternion, order w, x, y, z.
    pub q_sensor_target: [f64; 4],
    /// Position of the target origin in the sensor frame (m).
    pub p_sensor_target: [f64; 3],
    /// Fitness of the match (mean squared point distance, m²; seed 002 `f_conv`).
    pub f_conv_m2: f64,
    /// Acquisition compute time (ms).
    pub time_ms: f64,
    /// Instance that produced the result.
    pub instance: Name,
}

impl AcquisitionResult {
    /// A fresh result: schema set, identity rotation, not successful.
    pub fn new() -> Self {
        Self {
            schema: SCHEMA_VERSION,
            q_sensor_target: [1.0, 0.0, 0.0, 0.0],
            ..Self::default()
        }
    }

    /// The frame of the acquisition this record confirms, when it is a
    /// confirmation ([`Verification::Confirms`]) rather than an acquisition.
    pub fn confirms(&self) -> Option<u64> {
        (self.verification == Verification::Confirms as u8).then_some(self.sequence)
    }

    /// True when this record starts a track that awaits verification.
    pub fn pending(&self) -> bool {
        self.success == 1 && self.verification == Verification::Pending as u8
    }
}

impl WireMessage for AcquisitionResult {
    const KIND: u8 = 4;
    const MAX_WIRE_BYTES: usize = fixed_max_wire_bytes::<Self>();

    fn schema(&self) -> u16 {
        self.schema
    }

    fn validate(&self) -> Result<(), CodecError> {
        check_code("method", self.method, AcquisitionMethod::Given as u8)?;
        check_code("success", self.success, 1)?;
        check_code(
            "verification",
            self.verification,
            Verification::Confirms as u8,
        )?;
        check_name("instance", &self.instance)
    }
}
