//! What init reads from the wire (the tracker's estimates) and what it
//! writes (one `AcquisitionResult` per acquisition).

use crate::chain::Acquisition;
use crate::error::InitError;
use crate::state::EstimateInfo;
use spacepose_messages::{AcquisitionResult, Name, PoseEstimate, WireStatus};

impl EstimateInfo {
    /// Reads the fields of a wire estimate (a bad status code is an error).
    pub fn from_wire(e: &PoseEstimate) -> Result<Self, InitError> {
        let status = WireStatus::from_u8(e.status).map_err(|err| InitError::InvalidMessage {
            what: "PoseEstimate",
            reason: err.to_string(),
        })?;
        let started_ns = (e.published_ns > 0 && e.total_ms.is_finite() && e.total_ms >= 0.0)
            .then(|| e.published_ns - (e.total_ms * 1e6) as i64);
        Ok(Self {
            instance: e.instance,
            sequence: e.sequence,
            status,
            started_ns,
        })
    }
}

impl Acquisition {
    /// The message to publish for the frame `sequence` whose scan ended at
    /// `t_s`: success with the accepted method's pose and f_CONV, or failure
    /// (`success = 0`) with the best rejected f_CONV (NaN when no method
    /// produced a pose; the pose is then the identity at the origin and
    /// must not be used). `time_ms` is the whole acquisition's time.
    pub fn to_wire(&self, sequence: u64, t_s: f64, instance: Name) -> AcquisitionResult {
        let mut msg = AcquisitionResult::new();
        msg.sequence = sequence;
        msg.t_s = t_s;
        msg.instance = instance;
        msg.time_ms = self.time_ms;
        msg.f_conv_m2 = f64::NAN;
        let reported = self.reported();
        // A frame on which no method ran reports the first configured one.
        msg.method = reported.map_or(self.first_method, |a| a.method) as u8;
        if let Some(Ok(out)) = reported.map(|a| &a.outcome) {
            msg.f_conv_m2 = out.f_conv_m2;
            if out.accepted {
                msg.success = 1;
                msg.set_pose(&out.t_sensor_target);
            }
        }
        msg
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_status_codes_are_errors_and_the_start_is_published_minus_total() {
        let mut e = PoseEstimate::new();
        e.status = 9;
        assert!(EstimateInfo::from_wire(&e).is_err());
        e.status = WireStatus::Lost as u8;
        e.published_ns = 5_000_000;
        e.total_ms = 2.0;
        assert_eq!(
            EstimateInfo::from_wire(&e).unwrap().started_ns,
            Some(3_000_000)
        );
        // Unknown timing (never published, NaN duration): no start.
        e.total_ms = f64::NAN;
        assert_eq!(EstimateInfo::from_wire(&e).unwrap().started_ns, None);
        e.total_ms = 2.0;
        e.published_ns = 0;
        assert_eq!(EstimateInfo::from_wire(&e).unwrap().started_ns, None);
    }
}
