//! Chaser trajectories in the target's LVLH frame.
//!
//! LVLH convention used here: origin at the target centre of mass,
//! `x` along-track (V-bar), `y` opposite to the orbit normal (−H-bar),
//! `z` towards the Earth (−R-bar). The seed 000 rendezvous approaches along
//! `−y_LVLH`, so the chaser holds on the `+y_LVLH` axis.
//!
//! Times here are *trajectory* times `τ = compression · t`; velocities are
//! `dp/dτ`.

use crate::profile::{ramped_move, warp};
use nalgebra::Vector3;
use std::f64::consts::TAU;

/// Duration of the cosine velocity ramps at the ends of every approach leg (s).
const APPROACH_RAMP_S: f64 = 10.0;
/// Fly-around: azimuth amplitude (towards `+x_LVLH`) of the figure of eight.
const FLY_AROUND_AZIMUTH_DEG: f64 = 80.0;
/// Fly-around: elevation amplitude (towards `−z_LVLH`, away from the Earth).
const FLY_AROUND_ELEVATION_DEG: f64 = 25.0;

/// What the chaser does during one leg of the rendezvous.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LegMotion {
    /// Inspection at constant range: a figure of eight on the sphere of that
    /// radius around the target (azimuth ±80° in the `x-y` LVLH plane,
    /// elevation ±25°), starting and ending at rest at the hold point.
    FlyAround {
        /// Range to the target (m).
        range_m: f64,
    },
    /// Station keeping on the hold axis.
    Hold {
        /// Range to the target (m).
        range_m: f64,
    },
    /// Straight-line approach along `−y_LVLH`, rest to rest.
    Approach {
        /// Range at the start of the leg (m).
        from_m: f64,
        /// Range at the end of the leg (m).
        to_m: f64,
    },
}

/// One leg of a rendezvous, over `[start_s, end_s]` in trajectory time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leg {
    /// Start of the leg (s).
    pub start_s: f64,
    /// End of the leg (s).
    pub end_s: f64,
    /// The motion.
    pub motion: LegMotion,
}

/// A chaser trajectory: position and velocity in LVLH at trajectory time τ.
#[derive(Debug, Clone, PartialEq)]
pub enum ChaserTrajectory {
    /// Seed 000 §4.3/§4.4 rendezvous: successive legs, then a hold at the
    /// last range. LVLH is treated as inertial (the EPOS facility).
    Rendezvous {
        /// The legs, contiguous and in time order.
        legs: Vec<Leg>,
    },
    /// Seed 002 §4.3 passive safety ellipse (Clohessy-Wiltshire, drift-free):
    /// in Hill axes (radial, along-track, normal)
    /// `x = c sin θ, y = 2c cos θ, z = d cos θ`, `θ = n τ + θ₀`.
    SafetyEllipse {
        /// Radial semi-amplitude `c` (m): also the minimum range.
        radial_m: f64,
        /// Cross-track amplitude `d` (m): the maximum range is `√(4c² + d²)`.
        cross_track_m: f64,
        /// Mean motion `n` (rad/s).
        mean_motion: f64,
        /// Phase at `τ = 0` (rad).
        phase0: f64,
    },
}

impl ChaserTrajectory {
    /// Chaser position (m) and velocity `dp/dτ` (m/s) in LVLH.
    pub fn state(&self, tau: f64) -> (Vector3<f64>, Vector3<f64>) {
        match self {
            ChaserTrajectory::Rendezvous { legs } => rendezvous_state(legs, tau),
            ChaserTrajectory::SafetyEllipse {
                radial_m,
                cross_track_m,
                mean_motion,
                phase0,
            } => {
                let (c, d, n) = (*radial_m, *cross_track_m, *mean_motion);
                let (s, co) = (mean_motion * tau + phase0).sin_cos();
                // Hill (x_R, y_V, z_H) → LVLH (x = y_V, y = −z_H, z = −x_R).
                let p = Vector3::new(2.0 * c * co, -d * co, -c * s);
                let v = Vector3::new(-2.0 * c * s, d * s, -c * co) * n;
                (p, v)
            }
        }
    }

    /// Angular velocity of LVLH with respect to inertial space, in LVLH, per
    /// unit of trajectory time (rad/s): `−n y_LVLH` on orbit, zero in the
    /// laboratory.
    pub fn lvlh_rate(&self) -> Vector3<f64> {
        match self {
            ChaserTrajectory::Rendezvous { .. } => Vector3::zeros(),
            ChaserTrajectory::SafetyEllipse { mean_motion, .. } => {
                Vector3::new(0.0, -mean_motion, 0.0)
            }
        }
    }

    /// The LVLH direction the sensor's `y` ("down") axis leans towards. It is
    /// never close to the line of sight on these trajectories: nadir
    /// (`+z_LVLH`) for the rendezvous (the line of sight stays within 25° of
    /// the `x-y` plane), `+y_LVLH` for the ellipse (the line of sight stays
    /// more than 70° away from it).
    pub fn sensor_down_reference(&self) -> Vector3<f64> {
        match self {
            ChaserTrajectory::Rendezvous { .. } => Vector3::z(),
            ChaserTrajectory::SafetyEllipse { .. } => Vector3::y(),
        }
    }

    /// Natural duration in trajectory time (s): end of the last leg, or two
    /// orbits for the ellipse.
    pub fn duration(&self) -> f64 {
        match self {
            ChaserTrajectory::Rendezvous { legs } => legs.last().map_or(0.0, |l| l.end_s),
            ChaserTrajectory::SafetyEllipse { mean_motion, .. } => 2.0 * TAU / mean_motion,
        }
    }
}

fn rendezvous_state(legs: &[Leg], tau: f64) -> (Vector3<f64>, Vector3<f64>) {
    let Some(first) = legs.first() else {
        return (Vector3::zeros(), Vector3::zeros());
    };
    let leg = legs
        .iter()
        .find(|l| tau < l.end_s)
        .unwrap_or_else(|| legs.last().unwrap_or(first));
    let duration = leg.end_s - leg.start_s;
    let s = (tau - leg.start_s).clamp(0.0, duration);
    match leg.motion {
        LegMotion::Hold { range_m } => (Vector3::y() * range_m, Vector3::zeros()),
        LegMotion::Approach { from_m, to_m } => {
            let (u, du) = ramped_move(s, duration, APPROACH_RAMP_S);
            (
                Vector3::y() * (from_m + (to_m - from_m) * u),
                Vector3::y() * ((to_m - from_m) * du),
            )
        }
        LegMotion::FlyAround { range_m } => fly_around(s / duration, duration, range_m),
    }
}

/// Figure of eight at constant range: `az = A sin 2πσ`, `el = B sin 4πσ`
/// with the rest-to-rest warp `σ(u)`, `u = s / duration`.
fn fly_around(u: f64, duration: f64, range_m: f64) -> (Vector3<f64>, Vector3<f64>) {
    let (sigma, dsigma) = warp(u);
    let a = FLY_AROUND_AZIMUTH_DEG.to_radians();
    let b = FLY_AROUND_ELEVATION_DEG.to_radians();
    let az = a * (TAU * sigma).sin();
    let el = b * (2.0 * TAU * sigma).sin();
    let daz = a * TAU * (TAU * sigma).cos() * dsigma / duration;
    let del = b * 2.0 * TAU * (2.0 * TAU * sigma).cos() * dsigma / duration;
    let (saz, caz) = az.sin_cos();
    let (sel, cel) = el.sin_cos();
    let up = -Vector3::z();
    let horizontal = Vector3::y() * caz + Vector3::x() * saz;
    let d = horizontal * cel + up * sel;
    let d_az = (Vector3::x() * caz - Vector3::y() * saz) * cel;
    let d_el = -horizontal * sel + up * cel;
    (d * range_m, (d_az * daz + d_el * del) * range_m)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn legs() -> Vec<Leg> {
        vec![
            Leg {
                start_s: 0.0,
                end_s: 500.0,
                motion: LegMotion::FlyAround { range_m: 15.0 },
            },
            Leg {
                start_s: 500.0,
                end_s: 550.0,
                motion: LegMotion::Hold { range_m: 15.0 },
            },
            Leg {
                start_s: 550.0,
                end_s: 900.0,
                motion: LegMotion::Approach {
                    from_m: 15.0,
                    to_m: 8.0,
                },
            },
        ]
    }

    fn assert_velocity_matches(traj: &ChaserTrajectory, tau: f64) {
        let h = 1e-4;
        let (_, v) = traj.state(tau);
        let fd = (traj.state(tau + h).0 - traj.state(tau - h).0) / (2.0 * h);
        assert!(
            (v - fd).norm() < 1e-8 * (1.0 + v.norm()),
            "τ={tau}: {v:?} vs {fd:?}"
        );
    }

    #[test]
    fn rendezvous_is_continuous_with_consistent_velocity() {
        let traj = ChaserTrajectory::Rendezvous { legs: legs() };
        let mut tau = -5.0;
        while tau < 950.0 {
            assert_velocity_matches(&traj, tau);
            let (p0, _) = traj.state(tau - 1e-7);
            let (p1, _) = traj.state(tau + 1e-7);
            assert!((p1 - p0).norm() < 1e-6);
            tau += 0.731;
        }
        for tau in [0.0, 120.0, 250.0, 499.0, 520.0] {
            assert!((traj.state(tau).0.norm() - 15.0).abs() < 1e-12);
        }
        assert!((traj.state(0.0).0 - Vector3::y() * 15.0).norm() < 1e-12);
        assert!((traj.state(500.0).0 - Vector3::y() * 15.0).norm() < 1e-12);
        assert!((traj.state(2000.0).0 - Vector3::y() * 8.0).norm() < 1e-12);
    }

    #[test]
    fn safety_ellipse_obeys_clohessy_wiltshire() {
        let n = TAU / 6000.0;
        let traj = ChaserTrajectory::SafetyEllipse {
            radial_m: 25.0,
            cross_track_m: 309f64.sqrt(),
            mean_motion: n,
            phase0: 0.3,
        };
        let h = 1.0;
        for i in 0..50 {
            let tau = 240.0 * i as f64;
            assert_velocity_matches(&traj, tau);
            // Back to Hill axes: x_R = −z, y_V = x, z_H = −y.
            let hill = |p: Vector3<f64>| Vector3::new(-p.z, p.x, -p.y);
            let p = hill(traj.state(tau).0);
            let v = hill(traj.state(tau).1);
            let a = (hill(traj.state(tau + h).0) - 2.0 * p + hill(traj.state(tau - h).0)) / (h * h);
            let cw = Vector3::new(
                3.0 * n * n * p.x + 2.0 * n * v.y,
                -2.0 * n * v.x,
                -n * n * p.z,
            );
            assert!((a - cw).norm() < 1e-9, "{a:?} vs {cw:?}");
        }
    }
}
