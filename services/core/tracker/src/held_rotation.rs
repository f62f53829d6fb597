//! The rate of a held rotation, from the track before the hold (not in
//! seed 000).
//!
//! When the surface in view stops constraining a rotation (deos end-on at
//! the 3 m hold: the roll about the tower), the registration holds it at
//! its guess (`NdtParams::min_lever_arm_m`), so the roll follows the
//! filter's spin rate as it was when the hold began. That rate comes from a
//! filter tuned to follow changing relative rates in the fly-around: at the
//! 4 m hold its error along the spin still wanders by ±0.1-0.25°/s from
//! frame to frame, and whatever it is at the hold's start turns into a
//! roll drift (seed 1 deblur: 0.085°/s, 5.4° after 75 s; seed 13: 16°).
//!
//! The same constant-angular-velocity model as the filter's (Eq. 9) is
//! fitted instead over a long baseline: the angle turned about the held
//! axis (fixed in the target body) by the track's own poses over the last
//! `window_s` seconds of frames where that rotation was well constrained
//! (weakest lever arm at least `min_lever_arm_m`), by least squares on a
//! line. Over 50 frames with 0.1-0.2° of noise each the slope is good to
//! about 0.002°/s. While the hold lasts, each held result is turned about
//! that axis (with the translation that keeps the surface fitted, the
//! geometric information's Schur complement) so that its angle about the
//! axis follows the line: an extrapolation, not a measurement, which the
//! filter then fuses like the rest of the pose.

use nalgebra::{Matrix6, Rotation3, Vector3};
use serde::{Deserialize, Serialize};
use spacepose_geometry::{Pose, so3};
use spacepose_registration::Registration;
use spacepose_registration::weak_directions::{rotation_turn, rotations};
use std::collections::VecDeque;

/// Tuning of [`HeldRotation`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HeldRotationConfig {
    /// Off: a held rotation follows the filter's prediction (as before).
    pub enabled: bool,
    /// Length of the history the rate is fitted on (s).
    pub window_s: f64,
    /// A frame counts in the fit when its weakest rotation's lever arm is
    /// at least this (m): above the frames where NDT's cells, no longer
    /// held by the surface, drag the roll (3-5 cm before the 3 m hold).
    pub min_lever_arm_m: f64,
    /// Fewest frames in the fit; with fewer the hold keeps the filter's
    /// rate.
    pub min_samples: usize,
    /// Longest gap between two poses of the chain (s); the rotation
    /// between them must stay below 180° (below 72°/s at 2.5 s).
    pub max_gap_s: f64,
}

impl Default for HeldRotationConfig {
    fn default() -> Self {
        Self {
            enabled: true,
            window_s: 60.0,
            min_lever_arm_m: 0.055,
            min_samples: 20,
            max_gap_s: 2.5,
        }
    }
}

impl HeldRotationConfig {
    /// `Some(reason)` when a field is out of its domain (NaN included).
    pub fn invalid(&self) -> Option<(&'static str, f64)> {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !positive(self.window_s) {
            return Some(("held_rotation.window_s", self.window_s));
        }
        if !(self.min_lever_arm_m.is_finite() && self.min_lever_arm_m >= 0.0) {
            return Some(("held_rotation.min_lever_arm_m", self.min_lever_arm_m));
        }
        if self.min_samples < 2 {
            return Some(("held_rotation.min_samples", self.min_samples as f64));
        }
        if !positive(self.max_gap_s) {
            return Some(("held_rotation.max_gap_s", self.max_gap_s));
        }
        None
    }
}

/// Most poses kept (a hold of hours at 10 Hz); the oldest go first.
const MAX_HISTORY: usize = 100_000;

/// One pose of the track.
#[derive(Debug, Clone, Copy)]
struct Sample {
    t: f64,
    /// Rotation of `t_target_sensor`.
    r_ts: Rotation3<f64>,
    /// The held axis's rotation was well constrained (counts in the fit).
    good: bool,
}

/// The line an active hold follows.
#[derive(Debug, Clone, Copy)]
struct Line {
    /// The held axis in the target frame (unit).
    axis: Vector3<f64>,
    /// Angle about `axis` turned since the chain's first pose, at
    /// `t_ref` (rad), and its rate (rad/s): `φ(t) = phi_ref + rate (t − t_ref)`.
    phi_ref: f64,
    rate: f64,
    t_ref: f64,
    /// Standard deviations of `phi_ref` (rad) and `rate` (rad/s) from the
    /// fit's residuals (ordinary least squares).
    sigma_phi_ref: f64,
    sigma_rate: f64,
    /// The angle of the last pose of the chain and that pose.
    phi_last: f64,
    last: Sample,
}

/// What happened to a held result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeldCorrection {
    /// The fitted rate about the held axis (rad/s, target frame).
    pub rate_rad_s: f64,
    /// The turn applied to the result about the held axis (rad).
    pub turn_rad: f64,
    /// Standard deviation of the line's angle at the result's time (rad):
    /// `√(σ_ref² + σ_rate² (t − t_ref)²)`, an extrapolation's uncertainty
    /// (`crate::held_axes` publishes it as the held rotation's).
    pub sigma_rad: f64,
}

/// The track's recent poses and, during a hold, the line its held rotation
/// follows.
#[derive(Debug, Clone, Default)]
pub struct HeldRotation {
    config: HeldRotationConfig,
    history: VecDeque<Sample>,
    line: Option<Line>,
}

impl HeldRotation {
    /// An empty history.
    pub fn new(config: HeldRotationConfig) -> Self {
        Self {
            config,
            history: VecDeque::new(),
            line: None,
        }
    }

    /// A hold is following a fitted line (until a frame holds nothing).
    pub fn following(&self) -> bool {
        self.line.is_some()
    }

    /// The lever arm (m) below which a frame does not count in the fit.
    pub fn min_lever_arm_m(&self) -> f64 {
        self.config.min_lever_arm_m
    }

    /// Forgets everything (re-initialisation, loss).
    pub fn reset(&mut self) {
        self.history.clear();
        self.line = None;
    }

    /// Records the pose the track produced at `t` (a fused frame), and
    /// whether its rotations were all well constrained (`weakest lever
    /// arm ≥ min_lever_arm_m` and nothing held). A frame that held nothing
    /// ends the hold.
    pub fn record(&mut self, t: f64, t_target_sensor: &Pose, weakest_lever_arm_m: f64, held: bool) {
        let sample = Sample {
            t,
            r_ts: t_target_sensor.rotation,
            good: !held && weakest_lever_arm_m >= self.config.min_lever_arm_m,
        };
        if let Some(line) = self.line.as_mut() {
            if held {
                line.phi_last += turned(&line.last.r_ts, &sample.r_ts, &line.axis);
                line.last = sample;
            } else {
                self.line = None;
            }
        }
        if self
            .history
            .back()
            .is_some_and(|s| t - s.t > self.config.max_gap_s || t <= s.t)
        {
            self.history.clear();
        }
        self.history.push_back(sample);
        // The window reaches back from the newest well-constrained frame,
        // so a long hold keeps the frames its line was fitted on (a frame
        // that releases the hold refits the same line).
        let newest_good = self
            .history
            .iter()
            .rev()
            .find(|s| s.good)
            .map_or(t, |s| s.t);
        while self.history.len() > MAX_HISTORY
            || self
                .history
                .front()
                .is_some_and(|s| newest_good - s.t > self.config.window_s)
        {
            self.history.pop_front();
        }
    }

    /// Turns `t_target_sensor`, a result at `t` that held the rotation
    /// about `axis` (target frame), so that its angle about that axis
    /// follows the line fitted before the hold. `information` is the
    /// registration's geometric information (`δ = [rot; trans]`), whose
    /// Schur complement gives the translation that goes with the turn.
    /// `None` (result unchanged) when there is no usable fit.
    pub fn correct(
        &mut self,
        t: f64,
        t_target_sensor: &mut Pose,
        axis: &Vector3<f64>,
        information: &nalgebra::Matrix6<f64>,
    ) -> Option<HeldCorrection> {
        if !self.config.enabled {
            return None;
        }
        if self.line.is_none() {
            self.line = self.fit(axis);
        }
        let line = self.line?;
        if !(t > line.last.t && t - line.last.t <= self.config.max_gap_s) {
            self.line = None;
            return None;
        }
        let phi = line.phi_last + turned(&line.last.r_ts, &t_target_sensor.rotation, &line.axis);
        let turn = line.phi_ref + line.rate * (t - line.t_ref) - phi;
        *t_target_sensor = turn_about(t_target_sensor, &line.axis, turn, information);
        let dt = t - line.t_ref;
        Some(HeldCorrection {
            rate_rad_s: line.rate,
            turn_rad: turn,
            sigma_rad: (line.sigma_phi_ref.powi(2) + (line.sigma_rate * dt).powi(2)).sqrt(),
        })
    }

    /// The least-squares line of the angle turned about `axis` by the chain
    /// of recorded poses, over its well-constrained ones.
    fn fit(&self, axis: &Vector3<f64>) -> Option<Line> {
        let axis = axis.try_normalize(1e-12)?;
        let first = self.history.front()?;
        let (mut phi, mut prev) = (0.0, first);
        let mut points = Vec::with_capacity(self.history.len());
        for s in &self.history {
            phi += turned(&prev.r_ts, &s.r_ts, &axis);
            prev = s;
            if s.good {
                points.push((s.t, phi));
            }
        }
        if points.len() < self.config.min_samples {
            return None;
        }
        let n = points.len() as f64;
        let t_ref = points.iter().map(|p| p.0).sum::<f64>() / n;
        let phi_ref = points.iter().map(|p| p.1).sum::<f64>() / n;
        let stt: f64 = points.iter().map(|p| (p.0 - t_ref).powi(2)).sum();
        let stp: f64 = points.iter().map(|p| (p.0 - t_ref) * (p.1 - phi_ref)).sum();
        if stt <= 0.0 {
            return None;
        }
        let rate = stp / stt;
        let residual2: f64 = points
            .iter()
            .map(|p| (p.1 - phi_ref - rate * (p.0 - t_ref)).powi(2))
            .sum::<f64>()
            / (n - 2.0).max(1.0);
        Some(Line {
            axis,
            phi_ref,
            rate,
            t_ref,
            sigma_phi_ref: (residual2 / n).sqrt(),
            sigma_rate: (residual2 / stt).sqrt(),
            phi_last: phi,
            last: *prev,
        })
    }
}

/// The angle (rad) about `axis` (target frame) of the turn from `from` to
/// `to` (rotations of `t_target_sensor`): `Log(R_to R_fromᵀ) · axis`.
fn turned(from: &Rotation3<f64>, to: &Rotation3<f64>, axis: &Vector3<f64>) -> f64 {
    so3::log(&(to * from.inverse())).dot(axis)
}

/// `t_target_sensor` turned by `turn` (rad) about `axis` (unit, target
/// frame), with the translation that keeps the surface fitted: per unit
/// turn `−H_tt⁻¹ H_tr axis`, from the geometric `information`
/// (`δ = [rot; trans]`, its Schur complement).
pub fn turn_about(
    t_target_sensor: &Pose,
    axis: &Vector3<f64>,
    turn: f64,
    information: &nalgebra::Matrix6<f64>,
) -> Pose {
    t_target_sensor.oplus(&(rotation_turn(information, axis) * turn))
}

impl HeldRotation {
    /// A result that held one rotation, turned about it to follow the rate
    /// fitted before the hold, with the correction applied; any other
    /// result as it is, with `None`.
    pub fn follow(
        &mut self,
        t: f64,
        mut registration: Registration,
    ) -> (Registration, Option<HeldCorrection>) {
        if registration.degenerate_directions != 1 {
            return (registration, None);
        }
        let Some(h) = registration.geometric_information else {
            return (registration, None);
        };
        let correction = weakest_rotation(&h)
            .and_then(|axis| self.correct(t, &mut registration.t_target_sensor, &axis, &h));
        if let Some(c) = correction {
            tracing::debug!(
                t,
                rate_deg_s = c.rate_rad_s.to_degrees(),
                turn_deg = c.turn_rad.to_degrees(),
                sigma_deg = c.sigma_rad.to_degrees(),
                "held rotation follows the fitted rate"
            );
        }
        (registration, correction)
    }
}

/// The rotation axis (target frame) the geometric information `h`
/// (`δ = [rot; trans]`) constrains least once the translation is
/// marginalised out (the held one, as the registration's degeneracy
/// handling finds it); `None` when `h` is not usable.
pub(crate) fn weakest_rotation(h: &Matrix6<f64>) -> Option<Vector3<f64>> {
    rotations(h, 1).first().map(|d| d.axis)
}

/// `registration` with its held rotation (one, as [`weakest_rotation`]
/// finds it) turned to that of `reference`, with the translation that goes
/// with the turn; unchanged when it held none.
pub(crate) fn held_at(mut registration: Registration, reference: &Pose) -> Registration {
    if registration.degenerate_directions != 1 {
        return registration;
    }
    let Some(h) = registration.geometric_information else {
        return registration;
    };
    if let Some(axis) = weakest_rotation(&h) {
        let eps = reference.ominus(&registration.t_target_sensor);
        let turn = axis.dot(&eps.fixed_rows::<3>(0));
        registration.t_target_sensor = turn_about(&registration.t_target_sensor, &axis, turn, &h);
    }
    registration
}

#[cfg(test)]
#[path = "held_rotation_tests.rs"]
mod tests;
