//! How to read a recording: topic, time mapping and scan period.

use serde::{Deserialize, Serialize};
use spacepose_geometry::TimeMapping;

/// Scan period used for derived times when nothing else gives one (s): the
/// 10 Hz of common spinning lidars.
pub const DEFAULT_SCAN_PERIOD_S: f64 = 0.1;

/// Options of [`crate::open`] (a config table: `topic`, `time`, `scan_period_s`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InputOptions {
    /// Topic of the point-cloud channel (MCAP, bag); `None`: the only one.
    pub topic: Option<String>,
    /// Which field holds per-point times, its unit and base.
    pub time: TimeMapping,
    /// Scan period (s) for frames without a time field and without
    /// `truth.csv` times: derived times span `[start, start + period]`.
    /// `None`: the `truth.csv` median period, else [`DEFAULT_SCAN_PERIOD_S`].
    pub scan_period_s: Option<f64>,
}

impl InputOptions {
    /// Checks the options.
    ///
    /// # Errors
    /// A message naming the bad key: an empty topic, an empty time field, a
    /// scan period that is NaN, infinite or not positive.
    pub fn validate(&self) -> Result<(), String> {
        if self.topic.as_deref().is_some_and(|t| t.trim().is_empty()) {
            return Err("topic must not be empty".into());
        }
        self.time.validate()?;
        match self.scan_period_s {
            Some(p) if !(p.is_finite() && p > 0.0) => {
                Err(format!("scan_period_s must be finite and > 0, got {p}"))
            }
            _ => Ok(()),
        }
    }

    /// The scan period for derived times: the configured one, else
    /// `recorded_s`, else [`DEFAULT_SCAN_PERIOD_S`].
    pub fn scan_period_or(&self, recorded_s: Option<f64>) -> f64 {
        self.scan_period_s
            .or(recorded_s)
            .unwrap_or(DEFAULT_SCAN_PERIOD_S)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_validate_and_bad_values_fail() {
        assert!(InputOptions::default().validate().is_ok());
        let nan = InputOptions {
            scan_period_s: Some(f64::NAN),
            ..InputOptions::default()
        };
        assert!(nan.validate().unwrap_err().contains("scan_period_s"));
        let empty = InputOptions {
            topic: Some(String::new()),
            ..InputOptions::default()
        };
        assert!(empty.validate().unwrap_err().contains("topic"));
    }

    #[test]
    fn the_scan_period_is_configured_recorded_or_ten_hertz() {
        let o = InputOptions::default();
        assert_eq!(o.scan_period_or(None), DEFAULT_SCAN_PERIOD_S);
        assert_eq!(o.scan_period_or(Some(0.4)), 0.4);
        let set = InputOptions {
            scan_period_s: Some(0.05),
            ..o
        };
        assert_eq!(set.scan_period_or(Some(0.4)), 0.05);
    }
}
