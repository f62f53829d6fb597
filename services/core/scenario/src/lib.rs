//! Relative-motion scenarios with ground truth: slow-spin, tumbling, safety
//! ellipse, random attitudes. No sensor model and no bus: a [`Scenario`]
//! only says where the target is, how it is turned and how fast both change,
//! in the sensor frame, at any time.
//!
//! - `slow-spin` — seed 000 §4.3: target spinning at 1°/s about `y_LVLH`;
//!   fly-around at 15 m, approach along `−y_LVLH` to 8 m then 3 m.
//! - `tumbling` — seed 000 §4.4: torque-free axisymmetric target (inertia
//!   ratio 1.2, 10°/s spin, 1°/s transverse rate), same kind of approach.
//! - `ellipse` — seed 002 §4.3: passive safety ellipse, range 25-53 m, one
//!   frame every 50 s over two orbits (241 frames), target tumbling at 2°/s.
//! - `random` — seed 002 §4.3: independent frames at a fixed range with
//!   uniform 321 Euler angles.
//!
//! Figures (checked by the unit tests):
//! - slow-spin: 15 m over [0, 550] s (figure-of-eight fly-around, azimuth
//!   ±80°, elevation ±25°, then hold), 15 → 8 m over [550, 900] s, 8 m over
//!   [900, 970] s, 8 → 3 m over [970, 1470] s. Approach legs start and stop
//!   with 10 s cosine velocity ramps, so cruise is 2.06 and 1.02 cm/s.
//! - tumbling: inertia `diag(1.2, 1, 1)`, symmetry (spin) axis = body x (the
//!   roll axis), ω₀ = 10°/s along x + 1°/s along y, so `|ω| = 10.05°/s`.
//!   Nutation (axis to H) `atan(1/12) = 4.76°`; the axis cones about H at
//!   `Ω_p = |H|/I_t = √145 = 12.04°/s` (period 29.9 s) while ω turns in the
//!   body at `λ = 0.2 ω_a = 2°/s`. H is tilted 5.24° from `y_LVLH`, so the
//!   spin axis swings between 0.47° and 10.0° from `y_LVLH`. Legs: fly-around
//!   to 350 s, 15 → 8 m to 700 s, hold, 8 → 4 m over [750, 1150] s, hold,
//!   4 → 3 m over [1230, 1330] s, hold to 1380 s.
//! - ellipse: Hill amplitudes 25 m radial, 50 m along-track, 17.6 m
//!   cross-track (n = 2π/6000 s): range 25.0-53.0 m; target at 2°/s about
//!   body (0.48, −0.6, 0.64) from a seeded uniform attitude, inertial rate
//!   (LVLH rotates at n); 241 frames at 50 s.
//! - random: range exactly `range_m`, centre of mass off the boresight by up
//!   to ±1° per axis; yaw, pitch, roll uniform in the open intervals.
//! - look-away variant (any scenario, `ScenarioConfig::look_away`): the
//!   sensor turns 60° (default) about its `x` axis for whole frames, so they
//!   see no target; the truth stays exact (issue 5's reacquisition case).
//! - pointing error: 0.3° per axis, sinusoids with seeded periods in
//!   [90, 180] s (true clock), at most 0.42° off the boresight.
//!
//! `v` and `ω` are analytic (chaser velocity, look-at rate, pointing-error
//! rate through the right Jacobian, closed-form body rates); the tests hold
//! them to five-point finite differences of the pose within 1e-7 relative.
//!
//! The sensor rides on the chaser; its boresight (sensor `z`) looks at the
//! target centre of mass up to a smooth pointing error of a few tenths of a
//! degree, and its `y` axis leans towards a fixed LVLH direction. Frames and
//! conventions are those of `spacepose-geometry`.
#![forbid(unsafe_code)]

pub mod attitude;
mod builder;
pub mod chaser;
pub mod config;
pub mod error;
pub mod look_away;
pub mod pointing;
pub mod presets;
pub mod profile;
pub mod random;
pub mod relative;
pub mod scenario;
pub mod truth;

pub use builder::build;
pub use config::{ScenarioConfig, ScenarioKind};
pub use error::ScenarioError;
pub use look_away::{LookAway, LookingAway};
pub use random::random_frame_euler;
pub use scenario::Scenario;
pub use truth::TruthState;

#[cfg(test)]
mod tests;
