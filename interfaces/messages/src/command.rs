//! Commands from the ground or the CLI: reinit, mode, swap.

use crate::codec::{CodecError, WireMessage, check_code, check_name, fixed_max_wire_bytes};
use crate::convert::QUATERNION_NORM_TOLERANCE;
use crate::error::MessageError;
use crate::pose::TrackingMode;
use crate::{Name, SCHEMA_VERSION};
use iceoryx2::prelude::ZeroCopySend;
use serde::{Deserialize, Serialize};

/// What a command asks (stored as `u8` in [`Command::kind`]).
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum CommandKind {
    /// Re-initialise the track, from the pose in the command if it is non-zero.
    Reinit = 0,
    /// Switch the tracking mode to [`Command::mode`].
    Mode = 1,
    /// Swap the active tracker to [`Command::target_instance`].
    Swap = 2,
}

impl CommandKind {
    /// Decodes the `u8` code.
    pub fn from_u8(code: u8) -> Result<CommandKind, MessageError> {
        match code {
            0 => Ok(CommandKind::Reinit),
            1 => Ok(CommandKind::Mode),
            2 => Ok(CommandKind::Swap),
            _ => Err(MessageError::UnknownCode {
                what: "command kind",
                code,
            }),
        }
    }

    /// Lower-case name (`"reinit"`, `"mode"`, `"swap"`).
    pub fn as_str(self) -> &'static str {
        match self {
            CommandKind::Reinit => "reinit",
            CommandKind::Mode => "mode",
            CommandKind::Swap => "swap",
        }
    }
}

/// A command to one instance (or to all when `target_instance` is empty).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, Serialize, Deserialize)]
#[type_name("spacepose::Command")]
pub struct Command {
    /// Schema version of the sender ([`SCHEMA_VERSION`]).
    pub schema: u16,
    /// [`CommandKind`] code.
    pub kind: u8,
    /// [`TrackingMode::code`] for [`CommandKind::Mode`].
    pub mode: u8,
    /// Command counter of the issuer.
    pub sequence: u64,
    /// Instance the command is for; empty = every instance.
    pub target_instance: Name,
    /// Who issued the command (e.g. `"ground"`).
    pub issued_by: Name,
    /// Re-initialisation rotation of `t_sensor_target`, quaternion w, x, y, z
    /// (all zero = no pose given, use acquisition).
    pub q_sensor_target: [f64; 4],
    /// Re-initialisation position of the target in the sensor frame (m).
    pub p_sensor_target: [f64; 3],
}

impl Command {
    /// A command of `kind` from `issued_by`, for every instance, without a pose.
    pub fn new(kind: CommandKind, issued_by: Name) -> Self {
        Self {
            schema: SCHEMA_VERSION,
            kind: kind as u8,
            issued_by,
            ..Self::default()
        }
    }

    /// True when the command carries a re-initialisation pose.
    pub fn has_pose(&self) -> bool {
        self.q_sensor_target.iter().any(|&v| v != 0.0)
    }
}

impl WireMessage for Command {
    const KIND: u8 = 7;
    const MAX_WIRE_BYTES: usize = fixed_max_wire_bytes::<Self>();

    fn schema(&self) -> u16 {
        self.schema
    }

    /// Commands come from outside (the ground): besides the codes and names,
    /// a re-initialisation pose must be finite and its quaternion of unit
    /// norm (within [`QUATERNION_NORM_TOLERANCE`]); all zero = no pose.
    fn validate(&self) -> Result<(), CodecError> {
        check_code("kind", self.kind, CommandKind::Swap as u8)?;
        check_code("mode", self.mode, TrackingMode::MAX_CODE)?;
        check_name("target_instance", &self.target_instance)?;
        check_name("issued_by", &self.issued_by)?;
        let q = &self.q_sensor_target;
        if !q.iter().chain(&self.p_sensor_target).all(|v| v.is_finite()) {
            return Err(CodecError::Invalid(
                "non-finite re-initialisation pose".to_string(),
            ));
        }
        let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        if self.has_pose() && (norm - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
            return Err(CodecError::Invalid(format!(
                "re-initialisation quaternion of norm {norm} (expected 1)"
            )));
        }
        Ok(())
    }
}
