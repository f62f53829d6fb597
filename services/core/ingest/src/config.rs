//! Configuration of the ingest stage (TOML, `deny_unknown_fields`).

use crate::error::IngestError;
use serde::{Deserialize, Serialize};

/// Capacity of a frame when nothing else is configured: the cloud capacity of
/// the bus (`spacepose_messages::MAX_POINTS`).
pub const DEFAULT_MAX_POINTS: usize = 200_000;

/// An axis-aligned box (m): in the sensor frame for `static_box` (the part of
/// a test facility where the mockup hangs, used before acquisition), in the
/// target body frame for `body_box` (the target's bounding box).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisBox {
    /// Lower corner `[x, y, z]` (m, sensor frame).
    pub min_m: [f64; 3],
    /// Upper corner `[x, y, z]` (m, sensor frame).
    pub max_m: [f64; 3],
}

impl AxisBox {
    /// True when `p` (m, frame of the box) is inside the box, faces included.
    #[inline]
    pub fn contains(&self, p: [f64; 3]) -> bool {
        (0..3).all(|i| self.min_m[i] <= p[i] && p[i] <= self.max_m[i])
    }

    /// The box grown by `margin_m` on every side.
    pub fn grown(&self, margin_m: f64) -> AxisBox {
        AxisBox {
            min_m: self.min_m.map(|v| v - margin_m),
            max_m: self.max_m.map(|v| v + margin_m),
        }
    }

    /// The bounding box of `deos` in its body frame (rounded outward to the
    /// centimetre): prism and bars, tower along +x up to 1.6 m.
    pub fn deos() -> AxisBox {
        AxisBox {
            min_m: [-1.0, -0.9, -0.9],
            max_m: [1.6, 0.99, 0.9],
        }
    }
}

/// Finding the target in a frame without a prediction
/// ([`crate::detect`]), so that a facility's floor and walls are cropped
/// before the first acquisition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DetectConfig {
    /// Detect the target when there is no prediction (otherwise the static
    /// box or the range gate alone).
    pub enabled: bool,
    /// Distance from a plane within which a point lies on it (m): a sensor
    /// length (2.5 σ of the Mid-40's 2 cm range noise), not the target's.
    pub plane_tolerance_m: f64,
    /// Planes searched for background patches.
    pub max_planes: usize,
    /// Random triples tried per plane.
    pub ransac_iterations: usize,
    /// The plane search runs on about this many points of the frame.
    pub sample_points: usize,
    /// A plane with fewer of the sampled points than this fraction ends
    /// the search.
    pub min_plane_fraction: f64,
    /// The region about the detected centre has radius this times the
    /// bounding radius, plus the margin: the centre is that of the returns,
    /// which come from the near side only.
    pub crop_radius_factor: f64,
}

impl Default for DetectConfig {
    fn default() -> Self {
        DetectConfig {
            enabled: true,
            plane_tolerance_m: 0.05,
            max_planes: 4,
            ransac_iterations: 200,
            sample_points: 4096,
            min_plane_fraction: 0.05,
            crop_radius_factor: 1.5,
        }
    }
}

impl DetectConfig {
    fn validate(&self) -> Result<(), IngestError> {
        positive("detect.plane_tolerance_m", self.plane_tolerance_m)?;
        if self.sample_points < 3 {
            return Err(invalid(
                "detect.sample_points",
                self.sample_points as f64,
                "must be >= 3",
            ));
        }
        let f = self.min_plane_fraction;
        if !(f.is_finite() && (0.0..=1.0).contains(&f)) {
            return Err(invalid("detect.min_plane_fraction", f, "must be in [0, 1]"));
        }
        let c = self.crop_radius_factor;
        if !(c.is_finite() && c >= 1.0) {
            return Err(invalid(
                "detect.crop_radius_factor",
                c,
                "must be finite and >= 1",
            ));
        }
        Ok(())
    }
}

/// Parameters of the ingest stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct IngestConfig {
    /// Range gate, lower bound (m): closer returns (sensor window, dust) are dropped.
    pub min_range_m: f64,
    /// Range gate, upper bound (m): farther returns (facility walls) are dropped.
    pub max_range_m: f64,
    /// Radius of the sphere about the centre of mass that holds the target
    /// (m): `Target::bounding_radius()` (1.6008 m for `deos`).
    pub target_bounding_radius_m: f64,
    /// Added to the bounding radius (m): covers the prediction error, range
    /// noise and beam-divergence spread. Keep it below the clearance of the
    /// nearest facility structure (the simulator keeps floor and wall at
    /// least `bounding radius + 0.3 m` away).
    pub margin_m: f64,
    /// A prediction older than this at scan end (s) is not trusted and the
    /// frame is cropped as before acquisition.
    pub max_prediction_age_s: f64,
    /// Largest accepted frame (points); larger frames are rejected.
    pub max_points: usize,
    /// A forwarded frame with fewer points than this after the crop is counted (and logged) as "target not seen"
    /// (`IngestStats::frames_without_target`). Counting only: the frame is
    /// forwarded either way, and the tracker decides with its own
    /// `loss.min_points` whether it can register it. >= 1. Default 20, the
    /// init service's `min_points` and the tracker's `loss.min_points`.
    pub min_target_points: usize,
    /// Optional region of interest used before acquisition (no prediction),
    /// sensor frame.
    pub static_box: Option<AxisBox>,
    /// Optional bounding box of the target in its body frame. When the
    /// prediction carries an attitude, a point must also lie in this box
    /// grown by `margin_m`, at the pose predicted for the point's own time:
    /// it removes what touches the target (the robot arm) but lies outside
    /// its shape. `None` keeps the sphere alone.
    pub body_box: Option<AxisBox>,
    /// Finding the target without a prediction ([`DetectConfig`]).
    pub detect: DetectConfig,
}

impl Default for IngestConfig {
    /// 0.5-60 m range gate, `deos` bounding radius and body box, 0.25 m
    /// margin, 10 s prediction age, 200,000 points, target not
    /// seen below 20 points, no static box.
    fn default() -> Self {
        IngestConfig {
            min_range_m: 0.5,
            max_range_m: 60.0,
            target_bounding_radius_m: 1.6008,
            margin_m: 0.25,
            max_prediction_age_s: 10.0,
            max_points: DEFAULT_MAX_POINTS,
            min_target_points: 20,
            static_box: None,
            body_box: Some(AxisBox::deos()),
            detect: DetectConfig::default(),
        }
    }
}

impl IngestConfig {
    /// Rejects NaN, infinite, negative and inconsistent values.
    pub fn validate(&self) -> Result<(), IngestError> {
        non_negative("min_range_m", self.min_range_m)?;
        positive("max_range_m", self.max_range_m)?;
        if self.max_range_m <= self.min_range_m {
            return Err(invalid(
                "max_range_m",
                self.max_range_m,
                "must exceed min_range_m",
            ));
        }
        positive("target_bounding_radius_m", self.target_bounding_radius_m)?;
        non_negative("margin_m", self.margin_m)?;
        positive("max_prediction_age_s", self.max_prediction_age_s)?;
        if self.max_points == 0 {
            return Err(invalid("max_points", 0.0, "must be >= 1"));
        }
        if self.min_target_points == 0 {
            return Err(invalid("min_target_points", 0.0, "must be >= 1"));
        }
        if let Some(b) = &self.static_box {
            check_box("static_box.min_m", "static_box.max_m", b)?;
        }
        if let Some(b) = &self.body_box {
            check_box("body_box.min_m", "body_box.max_m", b)?;
        }
        self.detect.validate()
    }
}

fn check_box(min: &'static str, max: &'static str, b: &AxisBox) -> Result<(), IngestError> {
    for i in 0..3 {
        finite(min, b.min_m[i])?;
        finite(max, b.max_m[i])?;
        if b.max_m[i] <= b.min_m[i] {
            return Err(invalid(max, b.max_m[i], "must exceed min_m"));
        }
    }
    Ok(())
}

fn invalid(field: &'static str, value: f64, reason: &'static str) -> IngestError {
    IngestError::InvalidConfig {
        field,
        value,
        reason,
    }
}

fn finite(field: &'static str, value: f64) -> Result<(), IngestError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(invalid(field, value, "must be finite"))
    }
}

fn positive(field: &'static str, value: f64) -> Result<(), IngestError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(field, value, "must be finite and > 0"))
    }
}

fn non_negative(field: &'static str, value: f64) -> Result<(), IngestError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(invalid(field, value, "must be finite and >= 0"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_valid_and_round_trips_through_toml() {
        let c = IngestConfig::default();
        c.validate().unwrap();
        let text = toml::to_string(&c).unwrap();
        let back: IngestConfig = toml::from_str(&text).unwrap();
        assert_eq!(back, c);
    }

    #[test]
    fn partial_toml_takes_defaults_and_unknown_keys_fail() {
        let c: IngestConfig = toml::from_str(
            "margin_m = 0.1\n[static_box]\nmin_m = [-5.0, -5.0, 1.0]\nmax_m = [5.0, 5.0, 30.0]\n",
        )
        .unwrap();
        assert_eq!(c.margin_m, 0.1);
        assert!(c.static_box.unwrap().contains([0.0, 0.0, 10.0]));
        assert!(!c.static_box.unwrap().contains([0.0, 0.0, 40.0]));
        c.validate().unwrap();
        assert!(toml::from_str::<IngestConfig>("margin = 0.1").is_err());
    }

    #[test]
    fn validation_rejects_nan_and_inconsistent_values() {
        let bad = [
            IngestConfig {
                margin_m: f64::NAN,
                ..Default::default()
            },
            IngestConfig {
                min_range_m: 10.0,
                max_range_m: 5.0,
                ..Default::default()
            },
            IngestConfig {
                target_bounding_radius_m: 0.0,
                ..Default::default()
            },
            IngestConfig {
                max_points: 0,
                ..Default::default()
            },
            IngestConfig {
                min_target_points: 0,
                ..Default::default()
            },
            IngestConfig {
                static_box: Some(AxisBox {
                    min_m: [0.0, 0.0, f64::NAN],
                    max_m: [1.0, 1.0, 1.0],
                }),
                ..Default::default()
            },
            IngestConfig {
                body_box: Some(AxisBox {
                    min_m: [0.0, f64::INFINITY, 0.0],
                    max_m: [1.0, 1.0, 1.0],
                }),
                ..Default::default()
            },
            IngestConfig {
                static_box: Some(AxisBox {
                    min_m: [0.0, 0.0, 2.0],
                    max_m: [1.0, 1.0, 1.0],
                }),
                ..Default::default()
            },
        ];
        for c in bad {
            assert!(
                matches!(c.validate(), Err(IngestError::InvalidConfig { .. })),
                "{c:?}"
            );
        }
    }
}
