//! The paper scenarios: parameters and construction.

use crate::attitude::{AxisymmetricBody, TargetAttitude};
use crate::chaser::{ChaserTrajectory, Leg, LegMotion};
use crate::config::ScenarioConfig;
use crate::pointing::PointingError;
use crate::relative::RelativeMotion;
use nalgebra::{Rotation3, Unit, UnitQuaternion, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spacepose_geometry::so3;
use std::f64::consts::TAU;

/// Slow-spin (seed 000 §4.3): spin rate about `y_LVLH` (deg/s).
pub const SLOW_SPIN_RATE_DEG_S: f64 = 1.0;
/// Tumbling (seed 000 §4.4): axial spin rate (deg/s).
pub const TUMBLING_SPIN_DEG_S: f64 = 10.0;
/// Tumbling: transverse rate (deg/s); with the 1.2 inertia ratio it gives a
/// nutation of `atan(1 / 12) = 4.76°`.
pub const TUMBLING_TRANSVERSE_DEG_S: f64 = 1.0;
/// Tumbling: axial over transverse moment of inertia (seed 000 §4.4: 1.2).
pub const TUMBLING_INERTIA_RATIO: f64 = 1.2;
/// Tumbling: largest angle between the spin axis and `y_LVLH` (deg).
pub const TUMBLING_MAX_AXIS_TILT_DEG: f64 = 10.0;
/// Ellipse (seed 002 §4.3): LEO orbit period (s).
pub const ORBIT_PERIOD_S: f64 = 6000.0;
/// Ellipse: minimum range, the radial semi-amplitude (m).
pub const ELLIPSE_MIN_RANGE_M: f64 = 25.0;
/// Ellipse: maximum range, `√(4c² + d²)` (m).
pub const ELLIPSE_MAX_RANGE_M: f64 = 53.0;
/// Ellipse: inertial tumble rate of the target (deg/s).
pub const ELLIPSE_TUMBLE_DEG_S: f64 = 2.0;
/// Ellipse: tumble axis in the target body frame (normalised on use), off
/// the principal axes.
pub const ELLIPSE_TUMBLE_AXIS: [f64; 3] = [0.48, -0.6, 0.64];

/// Seed 000 §4.3 legs (trajectory time): fly-around at 15 m until 500 s,
/// hold, 15 → 8 m over [550, 900] s (2 cm/s), hold, 8 → 3 m over
/// [970, 1470] s (1 cm/s).
pub fn slow_spin_legs(range_scale: f64) -> Vec<Leg> {
    scaled(
        range_scale,
        vec![
            leg(0.0, 500.0, LegMotion::FlyAround { range_m: 15.0 }),
            leg(500.0, 550.0, LegMotion::Hold { range_m: 15.0 }),
            leg(
                550.0,
                900.0,
                LegMotion::Approach {
                    from_m: 15.0,
                    to_m: 8.0,
                },
            ),
            leg(900.0, 970.0, LegMotion::Hold { range_m: 8.0 }),
            leg(
                970.0,
                1470.0,
                LegMotion::Approach {
                    from_m: 8.0,
                    to_m: 3.0,
                },
            ),
        ],
    )
}

/// Seed 000 §4.4 legs (trajectory time): fly-around at 15 m until 350 s,
/// 15 → 8 m until 700 s (2 cm/s), hold 50 s, 8 → 4 m at 1 cm/s reaching 4 m
/// at 1150 s, hold 80 s, 4 → 3 m at 1 cm/s, hold until 1380 s (23 min).
pub fn tumbling_legs(range_scale: f64) -> Vec<Leg> {
    scaled(
        range_scale,
        vec![
            leg(0.0, 350.0, LegMotion::FlyAround { range_m: 15.0 }),
            leg(
                350.0,
                700.0,
                LegMotion::Approach {
                    from_m: 15.0,
                    to_m: 8.0,
                },
            ),
            leg(700.0, 750.0, LegMotion::Hold { range_m: 8.0 }),
            leg(
                750.0,
                1150.0,
                LegMotion::Approach {
                    from_m: 8.0,
                    to_m: 4.0,
                },
            ),
            leg(1150.0, 1230.0, LegMotion::Hold { range_m: 4.0 }),
            leg(
                1230.0,
                1330.0,
                LegMotion::Approach {
                    from_m: 4.0,
                    to_m: 3.0,
                },
            ),
            leg(1330.0, 1380.0, LegMotion::Hold { range_m: 3.0 }),
        ],
    )
}

/// The legs with every range multiplied by `k`.
fn scaled(k: f64, legs: Vec<Leg>) -> Vec<Leg> {
    legs.into_iter()
        .map(|l| Leg {
            motion: match l.motion {
                LegMotion::FlyAround { range_m } => LegMotion::FlyAround {
                    range_m: range_m * k,
                },
                LegMotion::Hold { range_m } => LegMotion::Hold {
                    range_m: range_m * k,
                },
                LegMotion::Approach { from_m, to_m } => LegMotion::Approach {
                    from_m: from_m * k,
                    to_m: to_m * k,
                },
            },
            ..l
        })
        .collect()
}

/// The fly-around range of the slow-spin and tumbling legs at range scale 1 (m).
pub const FLY_AROUND_RANGE_M: f64 = 15.0;

/// The range scale at which a target of bounding radius `radius_m` is seen
/// whole at the fly-around by a sensor of full field of view `fov_deg`:
/// its bounding sphere within 80 % of the half field of view, never below
/// 1 (the paper's legs), and the whole sphere within `max_range_m` (the
/// suite's range gate: ingest drops points beyond it), which wins.
/// Decision: a target that overfills the field of view is seen in part,
/// and template matching then accepts wrong poses
/// (docs/design/target-packages.md); 80 % leaves room for the pointing
/// error and the fly-around's parallax. deos (1.60 m) stays at 1 (it
/// would fit from 6.1 m); envisat (21.1 m about its body centre) would fit
/// from 80 m but is held at 38.9 m by a 60 m gate.
pub fn range_scale_to_fit(radius_m: f64, fov_deg: f64, max_range_m: f64) -> f64 {
    let half = 0.8 * 0.5 * fov_deg.to_radians();
    let fit = radius_m / half.sin() / FLY_AROUND_RANGE_M;
    let gate = (max_range_m - radius_m) / FLY_AROUND_RANGE_M;
    fit.min(gate).max(1.0)
}

fn leg(start_s: f64, end_s: f64, motion: LegMotion) -> Leg {
    Leg {
        start_s,
        end_s,
        motion,
    }
}

/// Body x (the roll axis of the built-in targets) along `+y_LVLH`, body z
/// along `+z_LVLH`, then turned by `phase` about `y_LVLH`.
fn roll_axis_on_y_lvlh(phase: f64) -> Rotation3<f64> {
    let align = Rotation3::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2);
    so3::exp(&(Vector3::y() * phase)) * align
}

/// The tumbling target: inertia `diag(1.2, 1, 1)` (symmetry axis = body x,
/// the roll axis), 10°/s spin and 1°/s transverse rate along body y, angular
/// momentum tilted from `y_LVLH` (about `x_LVLH`) by `10° − nutation` so the
/// spin axis reaches exactly 10° from `y_LVLH`, turned by `phase` about it.
pub fn tumbling_body(phase: f64) -> AxisymmetricBody {
    let spin = TUMBLING_SPIN_DEG_S.to_radians();
    let transverse = TUMBLING_TRANSVERSE_DEG_S.to_radians();
    let nutation = transverse.atan2(TUMBLING_INERTIA_RATIO * spin);
    let tilt = TUMBLING_MAX_AXIS_TILT_DEG.to_radians() - nutation;
    let h = Rotation3::from_axis_angle(&Vector3::x_axis(), tilt) * Vector3::y();
    AxisymmetricBody::with_momentum_along(
        TUMBLING_INERTIA_RATIO,
        1.0,
        Vector3::x_axis(),
        Vector3::y(),
        spin,
        transverse,
        Unit::new_normalize(h),
        phase,
    )
}

/// Pointing error of amplitude `amplitude_deg` with seeded periods in
/// [90, 180] s and phases.
fn pointing_error(amplitude_deg: f64, rng: &mut ChaCha8Rng) -> PointingError {
    PointingError {
        amplitude: amplitude_deg.to_radians(),
        periods_s: [rng.random_range(90.0..180.0), rng.random_range(90.0..180.0)],
        phases: [rng.random_range(0.0..TAU), rng.random_range(0.0..TAU)],
    }
}

fn relative(
    name: &'static str,
    cfg: &ScenarioConfig,
    trajectory: ChaserTrajectory,
    attitude: TargetAttitude,
    rng: &mut ChaCha8Rng,
) -> RelativeMotion {
    RelativeMotion {
        name,
        trajectory,
        attitude,
        pointing: pointing_error(cfg.pointing_error_deg, rng),
        compression: cfg.compression,
        frame_period_s: cfg.frame_period_s,
    }
}

/// Slow-spin: constant 1°/s spin about `y_LVLH` (= body x), seeded initial
/// spin phase.
pub(crate) fn slow_spin(cfg: &ScenarioConfig) -> RelativeMotion {
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    let r0 = roll_axis_on_y_lvlh(rng.random_range(0.0..TAU));
    let w_body = Vector3::x() * SLOW_SPIN_RATE_DEG_S.to_radians();
    let attitude = TargetAttitude::ConstantRate { r0, w_body };
    relative(
        "slow-spin",
        cfg,
        ChaserTrajectory::Rendezvous {
            legs: slow_spin_legs(cfg.range_scale),
        },
        attitude,
        &mut rng,
    )
}

/// Tumbling: closed-form torque-free motion of [`tumbling_body`] with a
/// seeded phase.
pub(crate) fn tumbling(cfg: &ScenarioConfig) -> RelativeMotion {
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    let attitude = TargetAttitude::TorqueFree(tumbling_body(rng.random_range(0.0..TAU)));
    relative(
        "tumbling",
        cfg,
        ChaserTrajectory::Rendezvous {
            legs: tumbling_legs(cfg.range_scale),
        },
        attitude,
        &mut rng,
    )
}

/// The seed 002 safety ellipse: radial amplitude 25 m, along-track 50 m,
/// cross-track `√(53² − 50²) = 17.6 m`, phase 0 at the far point (53 m).
pub fn safety_ellipse() -> ChaserTrajectory {
    let c = ELLIPSE_MIN_RANGE_M;
    ChaserTrajectory::SafetyEllipse {
        radial_m: c,
        cross_track_m: (ELLIPSE_MAX_RANGE_M.powi(2) - 4.0 * c * c).sqrt(),
        mean_motion: TAU / ORBIT_PERIOD_S,
        phase0: 0.0,
    }
}

/// Ellipse: uniformly drawn initial attitude, 2°/s about a body axis off
/// the principal axes (constant inertial rate).
pub(crate) fn ellipse(cfg: &ScenarioConfig) -> RelativeMotion {
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    let r0 = uniform_rotation(&mut rng);
    let axis = Vector3::from(ELLIPSE_TUMBLE_AXIS).normalize();
    let attitude = TargetAttitude::ConstantRate {
        r0,
        w_body: axis * ELLIPSE_TUMBLE_DEG_S.to_radians(),
    };
    relative("ellipse", cfg, safety_ellipse(), attitude, &mut rng)
}

/// Shoemake's uniform random rotation.
fn uniform_rotation(rng: &mut ChaCha8Rng) -> Rotation3<f64> {
    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let q = nalgebra::Quaternion::new(
        b * (TAU * u3).cos(),
        a * (TAU * u2).sin(),
        a * (TAU * u2).cos(),
        b * (TAU * u3).sin(),
    );
    UnitQuaternion::from_quaternion(q).to_rotation_matrix()
}
