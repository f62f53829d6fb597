//! Per-point times of recorded clouds: which field holds them, in which
//! unit, measured from what, and what to do when there is none.
//!
//! Recognised field names, tried in this order when no name is configured
//! ([`TIME_FIELD_NAMES`]), with the defaults used when the mapping does not
//! set a unit or a base:
//!
//! | name          | float values                 | integer values                |
//! |---------------|------------------------------|-------------------------------|
//! | `t`           | s, absolute (spacepose)      | ns, relative (Ouster)         |
//! | `time`        | s, relative (Velodyne)       | ns, relative                  |
//! | `timestamp`   | s, absolute (Hesai, RoboSense)| ns, absolute                 |
//! | `offset_time` | ns, relative                 | ns, relative (Livox)          |
//! | other (configured) | s, absolute             | ns, absolute                  |
//!
//! "Relative" times are offsets from the frame's reference time (the ROS
//! header stamp, or the `truth.csv` scan start of a PCD directory); the
//! reader of the container adds it ([`TimedCloud::into_absolute`]).
//!
//! With no time field, times are **derived**: spread linearly in point
//! order from the scan start to the scan end ([`derive_linear_times`]).
//! This is reported ([`PointTimes::Derived`]) so the caller can warn and
//! count it; a missing field never silently reads as t = 0.

use serde::{Deserialize, Serialize};

use crate::point::Point;

/// Time field names recognised without configuration, in order of preference.
pub const TIME_FIELD_NAMES: [&str; 4] = ["t", "time", "timestamp", "offset_time"];

/// Unit of the raw values of a time field.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TimeUnit {
    /// Seconds.
    S,
    /// Milliseconds.
    Ms,
    /// Microseconds.
    Us,
    /// Nanoseconds.
    Ns,
}

impl TimeUnit {
    /// Seconds per unit (`1.0` for [`TimeUnit::S`], so seconds pass bit-exact).
    pub fn seconds_per_unit(self) -> f64 {
        match self {
            Self::S => 1.0,
            Self::Ms => 1e-3,
            Self::Us => 1e-6,
            Self::Ns => 1e-9,
        }
    }
}

/// What the values of a time field are measured from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TimeBase {
    /// Absolute times on the sensor clock.
    Absolute,
    /// Offsets from the frame's reference time (header stamp, scan start).
    Relative,
}

/// How to find per-point times (a config table: `field`, `unit`, `base`).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TimeMapping {
    /// Name of the time field; `None` tries [`TIME_FIELD_NAMES`] in order.
    pub field: Option<String>,
    /// Unit of its values; `None` decides by name and type (module docs).
    pub unit: Option<TimeUnit>,
    /// What its values are measured from; `None` decides by name and type.
    pub base: Option<TimeBase>,
}

/// The time field chosen for a cloud, with its resolved unit and base.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct TimeField {
    /// Field name as found in the file.
    pub name: String,
    /// Unit of its raw values.
    pub unit: TimeUnit,
    /// What its values are measured from.
    pub base: TimeBase,
}

/// Where the per-point times of a cloud came from.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum PointTimes {
    /// A field of the cloud.
    Field(TimeField),
    /// No time field: spread linearly over the scan interval in point order.
    Derived,
}

impl TimeMapping {
    /// Checks the mapping: a configured field name must not be empty.
    ///
    /// # Errors
    /// A message naming the bad key.
    pub fn validate(&self) -> Result<(), String> {
        match &self.field {
            Some(name) if name.trim().is_empty() => Err("time.field must not be empty".into()),
            _ => Ok(()),
        }
    }

    /// Chooses the time field among the cloud's `fields` (name, and whether
    /// its values are integers). `Ok(None)` when no recognised name is
    /// present.
    ///
    /// # Errors
    /// A message when a configured field is absent (listing the fields).
    pub fn resolve<'a>(
        &self,
        fields: impl IntoIterator<Item = (&'a str, bool)> + Clone,
    ) -> Result<Option<TimeField>, String> {
        let find = |wanted: &str| fields.clone().into_iter().find(|(n, _)| *n == wanted);
        let found = match &self.field {
            Some(name) => Some(find(name).ok_or_else(|| {
                let names: Vec<&str> = fields.clone().into_iter().map(|(n, _)| n).collect();
                format!("time field {name:?} not in the cloud (fields: {names:?})")
            })?),
            None => TIME_FIELD_NAMES.iter().find_map(|n| find(n)),
        };
        Ok(found.map(|(name, integer)| {
            let (unit, base) = default_unit_and_base(name, integer);
            TimeField {
                name: name.to_owned(),
                unit: self.unit.unwrap_or(unit),
                base: self.base.unwrap_or(base),
            }
        }))
    }
}

/// The unit and base of a field by its name and value type (module table).
fn default_unit_and_base(name: &str, integer: bool) -> (TimeUnit, TimeBase) {
    use TimeBase::{Absolute, Relative};
    match (name, integer) {
        ("offset_time", _) => (TimeUnit::Ns, Relative),
        ("t" | "time", true) => (TimeUnit::Ns, Relative),
        ("t", false) => (TimeUnit::S, Absolute),
        ("time", false) => (TimeUnit::S, Relative),
        (_, true) => (TimeUnit::Ns, Absolute),
        (_, false) => (TimeUnit::S, Absolute),
    }
}

/// A cloud read with [`TimeMapping`]: `t` holds the field value in
/// seconds (absolute or relative as `time` says), or NaN with no field.
#[derive(Debug, Clone, PartialEq)]
pub struct TimedCloud {
    /// The points.
    pub points: Vec<Point>,
    /// The time field used, if any.
    pub time: Option<TimeField>,
}

impl TimedCloud {
    /// Makes every `t` absolute on the sensor clock: relative field times
    /// get `reference_s` added; with no field, times are derived linearly
    /// over `derive_interval_s` (start, end) in point order.
    pub fn into_absolute(
        mut self,
        reference_s: f64,
        derive_interval_s: (f64, f64),
    ) -> (Vec<Point>, PointTimes) {
        match self.time {
            Some(field) => {
                if field.base == TimeBase::Relative {
                    for p in &mut self.points {
                        p.t += reference_s;
                    }
                }
                (self.points, PointTimes::Field(field))
            }
            None => {
                let (start_s, end_s) = derive_interval_s;
                derive_linear_times(&mut self.points, start_s, end_s);
                (self.points, PointTimes::Derived)
            }
        }
    }
}

/// Sets `t` of the `i`-th of `n` points to `start_s + (end_s - start_s) *
/// i / (n - 1)` (a single point gets `start_s`).
pub fn derive_linear_times(points: &mut [Point], start_s: f64, end_s: f64) {
    let last = points.len().saturating_sub(1).max(1) as f64;
    for (i, p) in points.iter_mut().enumerate() {
        p.t = start_s + (end_s - start_s) * (i as f64 / last);
    }
}

#[cfg(test)]
#[path = "time_tests.rs"]
mod tests;
