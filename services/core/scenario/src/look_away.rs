//! A scenario variant in which the sensor looks away from the target for a
//! few frames and comes back: the chaser's pointing is offset by a fixed
//! angle about the sensor `x` axis, larger than the field of view, so those
//! frames see no target at all (the init service's loss-and-reacquisition
//! case, issue 5). The truth stays exact: inside the window the sensor frame
//! is simply turned by a constant rotation.
//!
//! The offset is a step between two frames: frame `k` ends at
//! `(k + 1) · period` and its scan starts after `k · period` whenever the
//! integration time is shorter than the period, so the window
//! `(first · period, (first + frames) · period]` holds whole scans only.

use crate::error::ScenarioError;
use crate::scenario::Scenario;
use crate::truth::TruthState;
use nalgebra::{Rotation3, Vector3};
use serde::{Deserialize, Serialize};
use spacepose_geometry::Pose;

/// Which frames the sensor looks away, and by how much.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LookAway {
    /// Index of the first frame looking away (frame 0 ends at `period`).
    pub first_frame: usize,
    /// Number of consecutive frames looking away (>= 1).
    pub frames: usize,
    /// Pointing offset about the sensor `x` axis (deg). It must exceed half
    /// the field of view plus the target's angular radius: the Livox Mid-40
    /// sees a 38.4° circle (19.2° half-angle) and `deos` (1.6 m bounding
    /// radius) spans 6.1° at 15 m, 17.7° at 5 m. Default 60°.
    pub angle_deg: f64,
}

impl LookAway {
    /// Default pointing offset (deg).
    pub const DEFAULT_ANGLE_DEG: f64 = 60.0;

    /// `frames` frames from `first_frame` with the default offset.
    pub fn frames(first_frame: usize, frames: usize) -> Self {
        Self {
            first_frame,
            frames,
            angle_deg: Self::DEFAULT_ANGLE_DEG,
        }
    }

    /// Rejects an empty window and an angle that is not finite or outside
    /// `(0, 180]` degrees.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        if self.frames == 0 {
            return Err(ScenarioError::InvalidLookAway("frames must be >= 1".into()));
        }
        if !(self.angle_deg.is_finite() && self.angle_deg > 0.0 && self.angle_deg <= 180.0) {
            return Err(ScenarioError::InvalidLookAway(format!(
                "angle_deg must be in (0, 180], got {}",
                self.angle_deg
            )));
        }
        Ok(())
    }

    /// True when frame `k` (0-based) looks away.
    pub fn covers_frame(&self, k: usize) -> bool {
        (self.first_frame..self.first_frame + self.frames).contains(&k)
    }
}

/// Any scenario with a [`LookAway`] window applied to its sensor pointing.
pub struct LookingAway {
    inner: Box<dyn Scenario>,
    start_s: f64,
    end_s: f64,
    /// `R_nominal_sensor`: the turned sensor frame in the nominal one.
    r_offset: Rotation3<f64>,
}

impl LookingAway {
    /// Wraps `inner` (whose frame period places the window).
    pub fn new(inner: Box<dyn Scenario>, look: &LookAway) -> Result<Self, ScenarioError> {
        look.validate()?;
        let period = inner.frame_period_s();
        Ok(Self {
            start_s: look.first_frame as f64 * period,
            end_s: (look.first_frame + look.frames) as f64 * period,
            r_offset: Rotation3::from_axis_angle(&Vector3::x_axis(), look.angle_deg.to_radians()),
            inner,
        })
    }

    /// True when the sensor looks away at `t` (window `(start, end]`).
    pub fn looks_away_at(&self, t: f64) -> bool {
        t > self.start_s && t <= self.end_s
    }

    /// `T_sensor_target = R_offsetᵀ T_nominal_target` inside the window.
    fn turn(&self, pose: &Pose) -> Pose {
        let r = self.r_offset.inverse();
        Pose::new(r * pose.rotation, r * pose.translation)
    }
}

impl Scenario for LookingAway {
    fn name(&self) -> &str {
        self.inner.name()
    }

    fn duration_s(&self) -> f64 {
        self.inner.duration_s()
    }

    fn frame_end_times(&self, frames: usize) -> Vec<f64> {
        self.inner.frame_end_times(frames)
    }

    fn state_at(&self, t: f64) -> TruthState {
        let state = self.inner.state_at(t);
        if !self.looks_away_at(t) {
            return state;
        }
        // A constant rotation of the sensor frame: positions and velocities
        // turn with it; ω is expressed in the target body frame and the
        // offset adds no rate, so it is unchanged.
        TruthState {
            t_sensor_target: self.turn(&state.t_sensor_target),
            v_sensor_target: self.r_offset.inverse() * state.v_sensor_target,
            ..state
        }
    }

    fn pose_at(&self, t: f64) -> Pose {
        let pose = self.inner.pose_at(t);
        if self.looks_away_at(t) {
            self.turn(&pose)
        } else {
            pose
        }
    }

    fn frame_period_s(&self) -> f64 {
        self.inner.frame_period_s()
    }

    fn natural_frame_count(&self) -> usize {
        self.inner.natural_frame_count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ScenarioConfig, ScenarioKind, build};

    /// Half the Mid-40 field of view (deg).
    const HALF_FOV_DEG: f64 = 19.2;
    /// `deos` bounding radius (m).
    const DEOS_RADIUS_M: f64 = 1.6008;

    /// Smallest angle between the boresight and any point of the target's
    /// bounding sphere (deg); 0 when the boresight crosses the sphere.
    fn nearest_angle_deg(pose: &Pose) -> f64 {
        let p = pose.translation;
        let off_axis = p.angle(&Vector3::z()).to_degrees();
        let radius = (DEOS_RADIUS_M / p.norm()).asin().to_degrees();
        (off_axis - radius).max(0.0)
    }

    #[test]
    fn frames_in_the_window_cannot_see_the_target_and_the_others_can() {
        let look = LookAway::frames(5, 4);
        let cfg = ScenarioConfig {
            seed: 7,
            look_away: Some(look),
            ..ScenarioConfig::default_for(ScenarioKind::Tumbling)
        };
        let s = build(&cfg).unwrap();
        let plain = build(&ScenarioConfig {
            look_away: None,
            ..cfg.clone()
        })
        .unwrap();
        let integration_s = 0.54;
        for (k, t_end) in s.frame_end_times(14).into_iter().enumerate() {
            for t in [t_end - integration_s, t_end - 0.3, t_end] {
                let angle = nearest_angle_deg(&s.pose_at(t));
                if look.covers_frame(k) {
                    assert!(angle > HALF_FOV_DEG, "frame {k} at {t}: {angle}°");
                } else {
                    assert!(angle < 1.0, "frame {k} at {t}: {angle}°");
                    assert_eq!(s.pose_at(t), plain.pose_at(t));
                }
            }
        }
    }

    #[test]
    fn the_truth_stays_exact_inside_the_window() {
        let cfg = ScenarioConfig {
            seed: 3,
            look_away: Some(LookAway::frames(2, 3)),
            ..ScenarioConfig::default_for(ScenarioKind::Tumbling)
        };
        let s = build(&cfg).unwrap();
        let plain = build(&ScenarioConfig {
            look_away: None,
            ..cfg
        })
        .unwrap();
        let t = 3.7;
        let (a, b) = (s.state_at(t), plain.state_at(t));
        // Same range, same body rate, a rigid turn of the sensor frame.
        assert!(
            (a.t_sensor_target.translation.norm() - b.t_sensor_target.translation.norm()).abs()
                < 1e-12
        );
        assert_eq!(a.w_target, b.w_target);
        assert!((a.v_sensor_target.norm() - b.v_sensor_target.norm()).abs() < 1e-12);
        assert!(a.t_sensor_target.error_to(&s.pose_at(t)).0 < 1e-12);
        // v is still the derivative of the position inside the window.
        let h = 1e-4;
        let fd = (s.pose_at(t + h).translation - s.pose_at(t - h).translation) / (2.0 * h);
        assert!(
            (fd - a.v_sensor_target).norm() < 1e-6,
            "{fd:?} vs {:?}",
            a.v_sensor_target
        );
        // The offset is 60° about sensor x.
        let r = Rotation3::from_axis_angle(&Vector3::x_axis(), 60f64.to_radians());
        let turned = r.inverse() * b.t_sensor_target.translation;
        assert!((a.t_sensor_target.translation - turned).norm() < 1e-12);
    }

    #[test]
    fn bad_windows_are_errors() {
        let base = ScenarioConfig::default_for(ScenarioKind::Tumbling);
        for look in [
            LookAway::frames(3, 0),
            LookAway {
                angle_deg: f64::NAN,
                ..LookAway::frames(3, 2)
            },
            LookAway {
                angle_deg: 0.0,
                ..LookAway::frames(3, 2)
            },
        ] {
            let cfg = ScenarioConfig {
                look_away: Some(look),
                ..base.clone()
            };
            assert!(matches!(
                build(&cfg),
                Err(ScenarioError::InvalidLookAway(_))
            ));
        }
    }
}
