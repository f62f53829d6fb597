//! JSON records of the messages that have no well-known schema.
//!
//! Poses, filter states, heartbeats and truth are recorded as the telemetry
//! JSON of `spacepose_messages::telemetry` (the one JSON view of each);
//! acquisitions, which telemetry does not carry, as [`AcquisitionRecord`].

use serde::{Deserialize, Serialize};
use spacepose_messages::{AcquisitionMethod, AcquisitionResult, MessageError, Verification};

/// An acquisition: how, whether it succeeded, and the pose it found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AcquisitionRecord {
    /// Instance that produced it.
    pub instance: String,
    /// `"truth"`, `"template-matching"` or `"cnn"`.
    pub method: String,
    /// Whether the pose is valid (the tracker and the filter take it).
    pub accepted: bool,
    /// `"trusted"`, `"pending"` (the track awaits its verification) or
    /// `"confirms"` (not an acquisition: confirms the one of `sequence`);
    /// recordings from before the field read `"trusted"`.
    #[serde(default = "trusted")]
    pub verification: String,
    /// Sequence of the cloud frame it was computed from.
    pub sequence: u64,
    /// Time of validity (s, sensor clock).
    pub t_s: f64,
    /// Rotation of `t_sensor_target`, unit quaternion `[w, x, y, z]`.
    pub q_sensor_target: [f64; 4],
    /// Position of the target origin in the sensor frame (m).
    pub p_sensor_target_m: [f64; 3],
    /// Fitness of the match (mean squared point distance, m²).
    pub f_conv_m2: f64,
    /// Compute time (ms).
    pub time_ms: f64,
}

impl AcquisitionRecord {
    /// The record of a wire acquisition.
    ///
    /// # Errors
    /// An unknown method code.
    pub fn from_wire(m: &AcquisitionResult) -> Result<Self, MessageError> {
        Ok(Self {
            instance: m.instance.as_str().to_string(),
            method: AcquisitionMethod::from_u8(m.method)?.as_str().to_string(),
            accepted: m.success == 1,
            verification: Verification::from_u8(m.verification)?.as_str().to_string(),
            sequence: m.sequence,
            t_s: m.t_s,
            q_sensor_target: m.q_sensor_target,
            p_sensor_target_m: m.p_sensor_target,
            f_conv_m2: m.f_conv_m2,
            time_ms: m.time_ms,
        })
    }
}

fn trusted() -> String {
    Verification::Trusted.as_str().to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_acquisition_names_its_method_and_refuses_unknown_codes() {
        let mut m = AcquisitionResult::new();
        m.method = AcquisitionMethod::TemplateMatching as u8;
        m.success = 1;
        m.sequence = 3;
        m.p_sensor_target = [0.0, 0.0, 40.0];
        let r = AcquisitionRecord::from_wire(&m).unwrap();
        assert_eq!(
            (r.method.as_str(), r.accepted, r.sequence),
            ("template-matching", true, 3)
        );
        assert_eq!(r.p_sensor_target_m, [0.0, 0.0, 40.0]);
        assert_eq!(r.verification, "trusted");
        m.verification = Verification::Pending as u8;
        assert_eq!(
            AcquisitionRecord::from_wire(&m).unwrap().verification,
            "pending"
        );
        m.verification = 7;
        assert!(AcquisitionRecord::from_wire(&m).is_err());
        m.verification = 0;
        m.method = 9;
        assert!(AcquisitionRecord::from_wire(&m).is_err());
        // A recording from before the field reads "trusted".
        let mut json = serde_json::to_value(&r).unwrap();
        json.as_object_mut().unwrap().remove("verification");
        let old: AcquisitionRecord = serde_json::from_value(json).unwrap();
        assert_eq!(old.verification, "trusted");
    }
}
