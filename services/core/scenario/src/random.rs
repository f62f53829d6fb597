//! Seed 002 §4.3, second scenario: independent frames at a fixed range with
//! yaw, pitch and roll drawn from uniform distributions.

use crate::scenario::{Scenario, evenly_spaced_end_times};
use crate::truth::TruthState;
use nalgebra::Vector3;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spacepose_geometry::{Euler321, Pose};
use std::f64::consts::{FRAC_PI_2, PI};

/// The 321 Euler angles of `R_sensor_target` for frame `frame` of the random
/// scenario: yaw in ]−180°, 180°[, pitch in ]−90°, 90°[, roll in
/// ]−180°, 180°[, each uniform. Depends only on `(seed, frame)` (ChaCha8
/// seeded with `seed`, stream `frame`).
pub fn random_frame_euler(seed: u64, frame: u64) -> Euler321 {
    let mut rng = frame_rng(seed, frame);
    let yaw = open_uniform(&mut rng, PI);
    let pitch = open_uniform(&mut rng, FRAC_PI_2);
    let roll = open_uniform(&mut rng, PI);
    Euler321::new(yaw, pitch, roll)
}

fn frame_rng(seed: u64, frame: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(frame);
    rng
}

/// Uniform in the open interval `]−half, half[`.
fn open_uniform(rng: &mut ChaCha8Rng, half: f64) -> f64 {
    loop {
        let x = rng.random_range(-half..half);
        if x > -half {
            return x;
        }
    }
}

/// Independent frames: the state is constant over each frame's scan
/// `(t_k − period, t_k]` and jumps between frames; both velocities are zero.
#[derive(Debug, Clone)]
pub struct RandomAttitudes {
    pub(crate) seed: u64,
    pub(crate) frame_period_s: f64,
    pub(crate) frames: usize,
    pub(crate) range_m: f64,
    pub(crate) lateral_offset_rad: f64,
}

impl RandomAttitudes {
    /// Index of the frame whose scan contains `t` (frame k ends at
    /// `(k + 1) · period`); times before the first frame belong to frame 0.
    pub fn frame_index(&self, t: f64) -> u64 {
        let k = (t / self.frame_period_s - 1e-9).ceil() - 1.0;
        if k.is_finite() && k > 0.0 {
            k as u64
        } else {
            0
        }
    }

    fn pose_of_frame(&self, frame: u64) -> Pose {
        let rotation = random_frame_euler(self.seed, frame).to_rotation();
        // Same stream, far ahead, so the Euler draws stay those of
        // `random_frame_euler`.
        let mut rng = frame_rng(self.seed, frame);
        rng.set_word_pos(1 << 40);
        let mut offset = || {
            if self.lateral_offset_rad > 0.0 {
                rng.random_range(-self.lateral_offset_rad..=self.lateral_offset_rad)
            } else {
                0.0
            }
        };
        let (ax, ay) = (offset(), offset());
        let direction = Vector3::new(ax.tan(), ay.tan(), 1.0).normalize();
        Pose::new(rotation, direction * self.range_m)
    }
}

impl Scenario for RandomAttitudes {
    fn name(&self) -> &str {
        "random"
    }

    fn duration_s(&self) -> f64 {
        (self.frames.saturating_sub(1)) as f64 * self.frame_period_s
    }

    fn frame_end_times(&self, frames: usize) -> Vec<f64> {
        evenly_spaced_end_times(self.frame_period_s, frames)
    }

    fn state_at(&self, t: f64) -> TruthState {
        TruthState {
            t,
            t_sensor_target: self.pose_at(t),
            v_sensor_target: Vector3::zeros(),
            w_target: Vector3::zeros(),
        }
    }

    fn pose_at(&self, t: f64) -> Pose {
        self.pose_of_frame(self.frame_index(t))
    }

    fn frame_period_s(&self) -> f64 {
        self.frame_period_s
    }
}
