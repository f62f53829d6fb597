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
//! The sensor rides on the chaser; its boresight (sensor `z`) looks at the
//! target centre of mass up to a smooth pointing error of a few tenths of a
//! degree, and its `y` axis leans towards a fixed LVLH direction. Frames and
//! conventions are those of `spacepose-geometry`.
#![forbid(unsafe_code)]

pub mod attitude;
pub mod chaser;
pub mod config;
pub mod error;
pub mod pointing;
pub mod presets;
pub mod profile;
pub mod random;
pub mod relative;
pub mod scenario;
pub mod truth;

pub use config::{ScenarioConfig, ScenarioKind};
pub use error::ScenarioError;
pub use random::random_frame_euler;
pub use scenario::Scenario;
pub use truth::TruthState;

/// Builds the scenario a (validated) configuration describes.
pub fn build(config: &ScenarioConfig) -> Result<Box<dyn Scenario>, ScenarioError> {
    config.validate()?;
    Ok(match config.kind {
        ScenarioKind::SlowSpin => Box::new(presets::slow_spin(config)),
        ScenarioKind::Tumbling => Box::new(presets::tumbling(config)),
        ScenarioKind::Ellipse => Box::new(presets::ellipse(config)),
        ScenarioKind::Random => Box::new(random::RandomAttitudes {
            seed: config.seed,
            frame_period_s: config.frame_period_s,
            frames: config.random_frames,
            range_m: config.range_m,
            lateral_offset_rad: config.lateral_offset_deg.to_radians(),
        }),
    })
}

#[cfg(test)]
mod tests;
