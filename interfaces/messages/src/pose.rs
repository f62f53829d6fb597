//! Pose estimates published by the tracker(s).

use crate::codec::{CodecError, WireMessage, check_code, check_name, fixed_max_wire_bytes};
use crate::error::MessageError;
use crate::{Name, SCHEMA_VERSION};
use iceoryx2::prelude::ZeroCopySend;
use serde::{Deserialize, Serialize};
pub use spacepose_tracker::TrackingMode;

/// Track status on the wire (stored as `u8` in [`PoseEstimate::status`]).
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum WireStatus {
    /// Registration converged with good quality.
    Tracking = 0,
    /// The registration's quality is doubtful (not fused). The pose is the
    /// tracker's filter prediction in `deblur` and `ct-ndt` modes, the
    /// doubted registration in `ndt` and `icp` modes.
    Degraded = 1,
    /// The track is lost and must be re-acquired.
    Lost = 2,
    /// As `Tracking` (converged, good quality, fused by the filter), but
    /// the acquisition that started the track awaits the init service's
    /// verification ([`crate::Verification::Pending`]): not to be acted on
    /// as a confirmed pose.
    Unconfirmed = 3,
}

impl WireStatus {
    /// Decodes the `u8` code.
    pub fn from_u8(code: u8) -> Result<WireStatus, MessageError> {
        match code {
            0 => Ok(WireStatus::Tracking),
            1 => Ok(WireStatus::Degraded),
            2 => Ok(WireStatus::Lost),
            3 => Ok(WireStatus::Unconfirmed),
            _ => Err(MessageError::UnknownCode {
                what: "status",
                code,
            }),
        }
    }

    /// Lower-case name (`"tracking"`, `"degraded"`, `"lost"`,
    /// `"unconfirmed"`).
    pub fn as_str(self) -> &'static str {
        match self {
            WireStatus::Tracking => "tracking",
            WireStatus::Degraded => "degraded",
            WireStatus::Lost => "lost",
            WireStatus::Unconfirmed => "unconfirmed",
        }
    }

    /// True for a registration the filter fuses: `tracking`, or
    /// `unconfirmed` (the same quality, the track's start not yet verified).
    pub fn is_tracked(self) -> bool {
        matches!(self, WireStatus::Tracking | WireStatus::Unconfirmed)
    }
}

/// The tracking mode of an estimate or a command, from its code (the
/// tracker's one [`TrackingMode`]).
pub fn mode_from_code(code: u8) -> Result<TrackingMode, MessageError> {
    TrackingMode::from_code(code).ok_or(MessageError::UnknownCode { what: "mode", code })
}

/// One pose estimate of `t_sensor_target` (target body frame -> sensor frame).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, Serialize, Deserialize)]
#[type_name("spacepose::PoseEstimate")]
pub struct PoseEstimate {
    /// Schema version of the sender ([`SCHEMA_VERSION`]).
    pub schema: u16,
    /// [`WireStatus`] code.
    pub status: u8,
    /// [`TrackingMode::code`] of the registration that produced the pose.
    pub mode: u8,
    /// Rotations the surface in view left free, held at the prediction or
    /// on the rate fitted before the hold (0-3): an extrapolation, whose
    /// uncertainty `covariance` carries (`spacepose_tracker::HeldAxes`).
    pub held_axes: u8,
    /// Translations the surface in view hardly constrained, held at the
    /// prediction (0-3), likewise extrapolated
    /// (`spacepose_registration::NdtParams::min_translation_cosine`).
    pub held_translations: u8,
    /// Registration iterations used.
    pub iterations: u32,
    /// Sequence of the cloud frame this pose was computed from.
    pub sequence: u64,
    /// With status `unconfirmed`: the frame of the acquisition whose
    /// confirmation the track awaits (a restarted init service takes the
    /// verification over from it); 0 otherwise.
    pub acquisition_sequence: u64,
    /// Time of validity of the pose (s, sensor clock; the scan end).
    pub t_s: f64,
    /// Tracker instance that produced the estimate (e.g. `"tracker-a"`).
    pub instance: Name,
    /// Rotation of `t_sensor_target` as a unit quaternion, order w, x, y, z.
    pub q_sensor_target: [f64; 4],
    /// Position of the target origin in the sensor frame (m).
    pub p_sensor_target: [f64; 3],
    /// Covariance of the left ⊕ perturbation `[rot (rad); trans (m)]` of
    /// `t_sensor_target`, row major; all zeros = unknown.
    pub covariance: [[f64; 6]; 6],
    /// Final registration cost (NDT score or ICP mean squared distance, m²).
    pub cost: f64,
    /// Number of inlier points of the registration.
    pub inliers: u32,
    /// Number of points used by the registration (after preprocessing).
    pub points_used: u32,
    /// Preprocessing time (ms).
    pub preprocess_ms: f64,
    /// Registration time (ms).
    pub registration_ms: f64,
    /// Total tracker compute time for the frame (ms).
    pub total_ms: f64,
    /// `published_ns` of the cloud this pose comes from (CLOCK_REALTIME, ns).
    pub cloud_published_ns: i64,
    /// CLOCK_REALTIME at send (ns since the Unix epoch).
    pub published_ns: i64,
}

impl PoseEstimate {
    /// A fresh estimate: schema set, identity rotation, everything else zero.
    pub fn new() -> Self {
        Self {
            schema: SCHEMA_VERSION,
            q_sensor_target: [1.0, 0.0, 0.0, 0.0],
            ..Self::default()
        }
    }

    /// The decoded status.
    pub fn wire_status(&self) -> Result<WireStatus, MessageError> {
        WireStatus::from_u8(self.status)
    }
}

impl WireMessage for PoseEstimate {
    const KIND: u8 = 2;
    const MAX_WIRE_BYTES: usize = fixed_max_wire_bytes::<Self>();

    fn schema(&self) -> u16 {
        self.schema
    }

    fn validate(&self) -> Result<(), CodecError> {
        check_code("status", self.status, WireStatus::Unconfirmed as u8)?;
        check_code("mode", self.mode, TrackingMode::MAX_CODE)?;
        check_code("held_axes", self.held_axes, 3)?;
        check_code("held_translations", self.held_translations, 3)?;
        check_name("instance", &self.instance)
    }

    fn set_published_ns(&mut self, ns: i64) {
        self.published_ns = ns;
    }
}
