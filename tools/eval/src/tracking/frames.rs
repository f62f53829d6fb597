//! The frames of an evaluation: those the simulated sensor of the suite
//! publishes (`spacepose_lidar_sim_node`'s configuration and frame source),
//! simulated in parallel batches ahead of the trackers.

use anyhow::{Context, Result};
use rayon::prelude::*;
use spacepose_lidar_sim::{Frame, FrameSource, ReturnKind};
use spacepose_lidar_sim_node::LidarSimConfig;
use spacepose_scenario::Scenario;

/// Frames simulated together (in parallel) before the trackers see them.
pub const BATCH_FRAMES: usize = 8;

/// Frames `first .. first + count` of `source`, in parallel; frame `k` has
/// its own random stream, as in the sensor process.
pub fn simulate_batch(source: &FrameSource, first: u64, count: usize) -> Result<Vec<Frame>> {
    (0..count as u64)
        .into_par_iter()
        .map(|i| {
            source
                .frame(first + i)
                .with_context(|| format!("simulating frame {}", first + i))
        })
        .collect()
}

/// The sensor's configuration for an evaluation: every sensor effect on,
/// the facility's background only when `clutter` (in orbit there is none),
/// an integration time (a whole frame period when the sensor scans
/// continuously: seed 000 §4.1, 1 Hz frames of 1 s), and the truth
/// acquisition of the first frame.
pub fn sensor_config(
    base: LidarSimConfig,
    integration_time_s: f64,
    clutter: bool,
) -> LidarSimConfig {
    LidarSimConfig {
        integration_time_s,
        clutter,
        truth_init: true,
        ..base
    }
}

/// The angle (deg) between the true attitude at the mean time of the
/// frame's target returns and at its end: the lag of a one-pose fit of the
/// blurred cloud. NaN for a frame without target returns.
pub fn blur_lag_deg(scenario: &dyn Scenario, frame: &Frame) -> f64 {
    let times: Vec<f64> = frame
        .points
        .iter()
        .zip(&frame.kinds)
        .filter(|(_, k)| **k == ReturnKind::Target)
        .map(|(p, _)| p.t)
        .collect();
    if times.is_empty() {
        return f64::NAN;
    }
    let t_mean = times.iter().sum::<f64>() / times.len() as f64;
    let (ang, _) = scenario
        .pose_at(t_mean)
        .error_to(&frame.truth.t_sensor_target);
    ang.to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;
    use spacepose_geometry::Point;
    use spacepose_scenario::{ScenarioConfig, ScenarioKind, build};

    fn point_at(t: f64) -> Point {
        Point {
            x: 0.0,
            y: 0.0,
            z: 10.0,
            intensity: 1.0,
            t,
        }
    }

    #[test]
    fn blur_lag_is_the_turn_since_the_mean_target_return() {
        let scenario = build(&ScenarioConfig::default_for(ScenarioKind::Tumbling)).unwrap();
        let end = scenario.frame_end_times(5)[4];
        let mut frame = Frame {
            points: vec![point_at(end - 1.0), point_at(end), point_at(end - 1.0)],
            kinds: vec![ReturnKind::Target, ReturnKind::Target, ReturnKind::Clutter],
            scan_start: end - 1.0,
            scan_end: end,
            truth: scenario.state_at(end),
        };
        // The clutter return does not count: the mean time is end − 0.5 s.
        let lag = blur_lag_deg(scenario.as_ref(), &frame);
        let (expected, _) = scenario
            .pose_at(end - 0.5)
            .error_to(&frame.truth.t_sensor_target);
        assert!((lag - expected.to_degrees()).abs() < 1e-9, "{lag}");
        // Half a second of a 10°/s tumble (plus its precession).
        assert!((4.0..7.0).contains(&lag), "{lag}");
        frame.kinds = vec![ReturnKind::Outlier; 3];
        assert!(blur_lag_deg(scenario.as_ref(), &frame).is_nan());
    }
}
