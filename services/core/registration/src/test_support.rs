//! Shared, lazily built fixtures for the unit tests.

use crate::ndt_map::NdtMap;
use crate::params::NdtMapParams;
use crate::synthetic::SyntheticTarget;
use nalgebra::Vector3;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spacepose_geometry::{Point, Pose, so3};
use std::sync::OnceLock;

/// The synthetic spacecraft sampled every centimetre.
pub fn target() -> &'static SyntheticTarget {
    static T: OnceLock<SyntheticTarget> = OnceLock::new();
    T.get_or_init(|| SyntheticTarget::spacecraft(0.01))
}

/// The default smoothed NDT map of [`target`].
pub fn map() -> &'static NdtMap {
    static M: OnceLock<NdtMap> = OnceLock::new();
    M.get_or_init(|| NdtMap::build(&target().model(), &NdtMapParams::default()).unwrap())
}

/// The true `t_sensor_target` of the static test frame: target 6 m ahead,
/// seen obliquely.
pub fn true_t_sensor_target() -> Pose {
    Pose::new(
        so3::exp(&Vector3::new(0.5, -0.7, 0.3)),
        Vector3::new(0.15, -0.1, 6.0),
    )
}

/// The noise-free static frame (2 cm voxels) seen at [`true_t_sensor_target`].
pub fn frame() -> &'static Vec<Point> {
    static F: OnceLock<Vec<Point>> = OnceLock::new();
    F.get_or_init(|| target().frame(&true_t_sensor_target(), 0.02))
}

/// `t_target_sensor` perturbed as the target would be: rotated by
/// `angle_rad` about a random axis through its centre of mass (the target
/// origin) and shifted by `dist_m` along a random direction,
/// `T' = (ΔR, Δp) ∘ T`.
pub fn perturb(truth: &Pose, angle_rad: f64, dist_m: f64, rng: &mut ChaCha8Rng) -> Pose {
    let mut unit = || {
        let v = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        v.normalize()
    };
    let (axis, dir) = (unit(), unit());
    let rot = so3::exp(&(axis * angle_rad));
    Pose::new(rot, dir * dist_m).compose(truth)
}

/// A seeded RNG.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}
