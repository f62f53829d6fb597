//! Smooth (C²) one-dimensional motion profiles used to build the chaser
//! trajectories: a rest-to-rest move with cosine velocity ramps, and a
//! rest-to-rest time warp for the fly-around.

use std::f64::consts::PI;

/// Rest-to-rest move over `[0, duration]`: the velocity rises as a half
/// cosine during `ramp`, stays constant, and falls symmetrically. Returns the
/// travelled fraction `u ∈ [0, 1]` and `du/ds` at time `s`. The acceleration
/// is continuous (zero at both ends of each ramp). The cruise velocity is
/// `1 / (duration - ramp)`, slightly above the no-ramp `1 / duration`.
pub fn ramped_move(s: f64, duration: f64, ramp: f64) -> (f64, f64) {
    let ramp = ramp.clamp(0.0, duration / 2.0);
    if s <= 0.0 {
        return (0.0, 0.0);
    }
    if s >= duration {
        return (1.0, 0.0);
    }
    let cruise = 1.0 / (duration - ramp);
    // Distance and speed after time s inside a rising ramp.
    let rising = |s: f64| -> (f64, f64) {
        if ramp <= 0.0 {
            return (s, 1.0);
        }
        let x = PI * s / ramp;
        (s / 2.0 - ramp / (2.0 * PI) * x.sin(), (1.0 - x.cos()) / 2.0)
    };
    if s < ramp {
        let (d, v) = rising(s);
        (cruise * d, cruise * v)
    } else if s <= duration - ramp {
        (cruise * (ramp / 2.0 + s - ramp), cruise)
    } else {
        let (d, v) = rising(duration - s);
        (1.0 - cruise * d, cruise * v)
    }
}

/// Rest-to-rest time warp `σ(u) = u - sin(2πu) / 2π` on `[0, 1]`, with
/// `σ'(u) = 1 - cos(2πu)` and `σ''` both zero at the ends. Returns `(σ, σ')`.
pub fn warp(u: f64) -> (f64, f64) {
    let u = u.clamp(0.0, 1.0);
    let x = 2.0 * PI * u;
    (u - x.sin() / (2.0 * PI), 1.0 - x.cos())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramped_move_goes_from_rest_to_rest_and_derivative_matches() {
        let (duration, ramp) = (350.0, 10.0);
        assert_eq!(ramped_move(0.0, duration, ramp), (0.0, 0.0));
        assert_eq!(ramped_move(duration, duration, ramp), (1.0, 0.0));
        let h = 1e-4;
        let mut s = 0.37;
        while s < duration {
            let (u, du) = ramped_move(s, duration, ramp);
            let fd = (ramped_move(s + h, duration, ramp).0 - ramped_move(s - h, duration, ramp).0)
                / (2.0 * h);
            assert!((0.0..=1.0).contains(&u));
            assert!((du - fd).abs() < 1e-9, "s={s}: {du} vs {fd}");
            s += 3.1;
        }
        // Continuous across the ramp ends.
        for edge in [ramp, duration - ramp] {
            let a = ramped_move(edge - 1e-9, duration, ramp);
            let b = ramped_move(edge + 1e-9, duration, ramp);
            assert!((a.0 - b.0).abs() < 1e-10 && (a.1 - b.1).abs() < 1e-10);
        }
        // Cruise speed: 7 m in 350 s with 10 s ramps is 7/340 m/s.
        assert!((ramped_move(100.0, duration, ramp).1 * 7.0 - 7.0 / 340.0).abs() < 1e-15);
    }

    #[test]
    fn warp_is_monotonic_and_rest_to_rest() {
        assert_eq!(warp(0.0), (0.0, 0.0));
        let (end, d_end) = warp(1.0);
        assert!((end - 1.0).abs() < 1e-15 && d_end.abs() < 1e-15);
        let mut last = -1.0;
        for i in 0..=100 {
            let (s, ds) = warp(i as f64 / 100.0);
            assert!(s >= last && ds >= 0.0);
            last = s;
        }
    }
}
