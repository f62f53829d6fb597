//! Construction of the scenario a configuration describes: the presets,
//! the random attitudes, and the look-away wrapper around either.

use crate::config::{ScenarioConfig, ScenarioKind};
use crate::error::ScenarioError;
use crate::look_away::LookingAway;
use crate::scenario::Scenario;
use crate::{presets, random};

/// Builds the scenario a (validated) configuration describes.
pub fn build(config: &ScenarioConfig) -> Result<Box<dyn Scenario>, ScenarioError> {
    config.validate()?;
    let scenario: Box<dyn Scenario> = match config.kind {
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
    };
    Ok(match &config.look_away {
        Some(look) => Box::new(LookingAway::new(scenario, look)?),
        None => scenario,
    })
}
