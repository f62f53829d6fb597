//! The frames of a simulated run: a scenario seen by the simulator, frame
//! `k` with its own random stream, on a sensor clock that keeps running
//! when the scenario starts over. The `spacepose-lidar-sim` process and
//! `spacepose eval` take their frames from here, so both see the same ones.

use crate::config::SensorConfig;
use crate::error::SimError;
use crate::mismatch::Mismatch;
use crate::simulator::{Frame, LidarSimulator};
use spacepose_model::Target;
use spacepose_scenario::Scenario;
use std::sync::Arc;

/// A scenario, a simulator and a seed.
pub struct FrameSource {
    simulator: LidarSimulator,
    scenario: Box<dyn Scenario>,
    /// Frames of one pass of the scenario.
    pass_frames: u64,
    seed: u64,
    /// The world's departures from the model, when simulated.
    mismatch: Option<Mismatch>,
}

impl FrameSource {
    /// The frames of `scenario` seen by `sensor` looking at `target`, with
    /// the random streams of `seed`.
    ///
    /// # Errors
    /// An invalid sensor configuration.
    pub fn new(
        target: Arc<Target>,
        scenario: Box<dyn Scenario>,
        sensor: SensorConfig,
        seed: u64,
    ) -> Result<Self, SimError> {
        let simulator = LidarSimulator::new(target, sensor)?;
        let pass_frames = scenario.natural_frame_count().max(1) as u64;
        Ok(FrameSource {
            simulator,
            scenario,
            pass_frames,
            seed,
            mismatch: None,
        })
    }

    /// The frames of `nominal` as built and moving as the world moves
    /// ([`crate::mismatch`]): the target the sensor sees is
    /// `mismatch.as_built` applied to `nominal` with the run's `seed`,
    /// and each scan follows the scenario's own motion with the chaser's
    /// jitter and acceleration. The truth is the as-built target's.
    ///
    /// # Errors
    /// An invalid sensor configuration or mismatch, or an as-built mesh
    /// that cannot be built.
    pub fn with_mismatch(
        nominal: &Target,
        scenario: Box<dyn Scenario>,
        sensor: SensorConfig,
        seed: u64,
        mismatch: Mismatch,
    ) -> Result<Self, SimError> {
        mismatch.validate()?;
        let as_built = mismatch
            .as_built
            .apply(nominal, seed)
            .map_err(|e| SimError::Mismatch(e.to_string()))?;
        let mut source = FrameSource::new(Arc::new(as_built), scenario, sensor, seed)?;
        source.mismatch = Some(mismatch);
        Ok(source)
    }

    /// The scenario.
    pub fn scenario(&self) -> &dyn Scenario {
        self.scenario.as_ref()
    }

    /// The simulator.
    pub fn simulator(&self) -> &LidarSimulator {
        &self.simulator
    }

    /// Frames in one pass of the scenario.
    pub fn pass_frames(&self) -> u64 {
        self.pass_frames
    }

    /// Frame `k`: the scenario's frame `k mod pass` (its scan ends at
    /// `(k mod pass + 1)` frame periods), shifted by the passes before it,
    /// with the random stream [`LidarSimulator::frame_rng`]`(seed, k)`.
    ///
    /// # Errors
    /// The simulator's, for a state it cannot render.
    pub fn frame(&self, k: u64) -> Result<Frame, SimError> {
        let period = self.scenario.frame_period_s();
        let pass = k / self.pass_frames;
        let t_scenario = (k % self.pass_frames + 1) as f64 * period;
        let shift = (pass * self.pass_frames) as f64 * period;
        let mut rng = LidarSimulator::frame_rng(self.seed, k);
        let mut frame = match &self.mismatch {
            None => {
                let truth = self.scenario.state_at(t_scenario);
                self.simulator.try_simulate(&truth, &mut rng)?
            }
            Some(m) => {
                let window = (
                    t_scenario - self.simulator.config().integration_time_s,
                    t_scenario,
                );
                let (path, truth) = m.scan_path(self.scenario.as_ref(), window, self.seed, k);
                self.simulator.try_simulate_along(&truth, &path, &mut rng)?
            }
        };
        if shift != 0.0 {
            frame.scan_start += shift;
            frame.scan_end += shift;
            frame.truth.t += shift;
            for p in &mut frame.points {
                p.t += shift;
            }
        }
        Ok(frame)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spacepose_scenario::{ScenarioConfig, ScenarioKind, build};

    fn source(frames: usize) -> FrameSource {
        let mut sc = ScenarioConfig::default_for(ScenarioKind::Random);
        sc.random_frames = frames;
        sc.seed = 3;
        let target = Arc::new(Target::builtin("deos").unwrap());
        let mut sensor = SensorConfig::livox_mid40();
        sensor.integration_time_s = 0.1;
        FrameSource::new(target, build(&sc).unwrap(), sensor, 3).unwrap()
    }

    #[test]
    fn frames_are_reproducible_and_the_clock_runs_on_across_passes() {
        let s = source(2);
        assert_eq!(s.pass_frames(), 2);
        let a = s.frame(1).unwrap();
        let b = s.frame(1).unwrap();
        assert_eq!(a.points, b.points);
        let period = s.scenario().frame_period_s();
        assert!((a.scan_end - 2.0 * period).abs() < 1e-9);
        // Frame 3 is frame 1 of the second pass, two periods later.
        let c = s.frame(3).unwrap();
        assert!((c.scan_end - a.scan_end - 2.0 * period).abs() < 1e-9);
        assert!((c.truth.t - c.scan_end).abs() < 1e-9);
    }

    /// With a mismatch the frames show another target moving another way,
    /// the same for one seed; the truth is that target's, at the scan end.
    #[test]
    fn a_mismatched_source_renders_the_target_as_built() {
        let mut sc = ScenarioConfig::default_for(ScenarioKind::Tumbling);
        sc.seed = 4;
        let nominal = Target::builtin("deos").unwrap();
        let mut sensor = SensorConfig::livox_mid40();
        sensor.integration_time_s = 0.2;
        let plain = FrameSource::new(
            Arc::new(nominal.clone()),
            build(&sc).unwrap(),
            sensor.clone(),
            4,
        )
        .unwrap();
        let world = || {
            FrameSource::with_mismatch(
                &nominal,
                build(&sc).unwrap(),
                sensor.clone(),
                4,
                Mismatch::default(),
            )
            .unwrap()
        };
        let (a, b) = (world().frame(2).unwrap(), world().frame(2).unwrap());
        assert_eq!(a.points, b.points);
        let p = plain.frame(2).unwrap();
        assert_ne!(a.points, p.points);
        assert!(world().simulator().target().name().ends_with("as built"));
        // The truth differs from the scenario's by the jitter only.
        let (ang, pos) = a.truth.t_sensor_target.error_to(&p.truth.t_sensor_target);
        assert!(ang.to_degrees() < 0.2 && pos < 0.1, "{ang} {pos}");
        let bad = Mismatch {
            jitter_deg: -1.0,
            ..Mismatch::default()
        };
        assert!(FrameSource::with_mismatch(&nominal, build(&sc).unwrap(), sensor, 4, bad).is_err());
    }
}
