//! Scan patterns: the Livox Mid-40 rosette (seed 004 §IV.A) and the raster
//! of seed 002 §4.1.
//!
//! Directions are unit vectors in the sensor frame (z boresight, x right,
//! y down). Each ray of a frame gets its own timestamp; rays are produced in
//! time order, so timestamps are non-decreasing in scan order.

use nalgebra::Vector3;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// Rotation rate of the first Risley prism of the Mid-40 model (Hz).
///
/// The Mid-40 steers its beam with two wedge prisms turning in opposite
/// directions (Brazeal et al. 2021, seed 004 ref. 58). We use the rates
/// published for the Livox rosette, about 7294 rpm and -4664 rpm
/// (121.57 Hz and -77.73 Hz). Their ratio (-0.6394...) is far from any small
/// rational number: the closed pattern period is 1/gcd = 30 s, so successive
/// sub-second integration windows never retrace each other (non-repetitive).
pub const MID40_PRISM1_HZ: f64 = 7294.0 / 60.0;
/// Rotation rate of the second Risley prism (Hz, counter-rotating).
pub const MID40_PRISM2_HZ: f64 = -4664.0 / 60.0;
/// Full circular field of view of the Livox Mid-40 (deg).
pub const MID40_FOV_DEG: f64 = 38.4;

/// How the sensor sweeps its field of view.
#[derive(Debug, Clone, PartialEq)]
pub enum ScanPattern {
    /// Non-repetitive rosette: the sum of two counter-rotating Risley prism
    /// deflections of equal magnitude `fov/4` (first-order prism model).
    ///
    /// With equal deflections `δ`, the off-boresight angle is
    /// `|ψ| = 2δ |cos(π (f1 - f2) t + c)|`: every petal runs from the centre to
    /// the edge and back, and the petals precess by `π (f1 + f2) / (f1 - f2)`
    /// each. Time is spent uniformly in the phase, so the angular density per
    /// unit solid angle goes like `1 / (θ sqrt(θ_max² - θ²))`: densest at the
    /// centre, as on the real sensor (seed 004 §V: "scans more points in the
    /// middle of the field of view").
    Rosette {
        /// Full circular field of view (deg); 38.4 for the Mid-40.
        fov_deg: f64,
        /// Rotation rates of the two prisms (Hz, opposite signs).
        prism_rates_hz: [f64; 2],
    },
    /// Row-by-row raster on a regular azimuth/elevation grid (seed 002 §4.1:
    /// 40°x40° at 1°). The grid includes both edges: `round(fov/step) + 1`
    /// directions per axis (41x41 for the seed-002 sensor).
    Raster {
        /// Horizontal (azimuth, about y) field of view (deg).
        fov_x_deg: f64,
        /// Vertical (elevation, about x) field of view (deg).
        fov_y_deg: f64,
        /// Angular step in both axes (deg).
        step_deg: f64,
    },
}

impl ScanPattern {
    /// The Livox Mid-40 rosette.
    pub fn livox_mid40() -> Self {
        ScanPattern::Rosette {
            fov_deg: MID40_FOV_DEG,
            prism_rates_hz: [MID40_PRISM1_HZ, MID40_PRISM2_HZ],
        }
    }

    /// The 40°x40° raster at 1° of seed 002 §4.1.
    pub fn raster_seed002() -> Self {
        ScanPattern::Raster {
            fov_x_deg: 40.0,
            fov_y_deg: 40.0,
            step_deg: 1.0,
        }
    }

    /// Grid size `(columns, rows)` of a raster; `None` for a rosette.
    pub fn raster_grid(&self) -> Option<(usize, usize)> {
        match *self {
            ScanPattern::Raster {
                fov_x_deg,
                fov_y_deg,
                step_deg,
            } => Some((
                (fov_x_deg / step_deg).round() as usize + 1,
                (fov_y_deg / step_deg).round() as usize + 1,
            )),
            ScanPattern::Rosette { .. } => None,
        }
    }

    /// Number of rays of one frame (as a float, so absurd values can be
    /// rejected before conversion).
    pub fn ray_count(&self, integration_time_s: f64, points_per_second: f64) -> f64 {
        match self.raster_grid() {
            Some((nx, ny)) => (nx * ny) as f64,
            None => (integration_time_s * points_per_second).round(),
        }
    }

    /// The rays of one frame over `[scan_end - integration_time, scan_end]`.
    ///
    /// A rosette starts at a random prism phase (seed 004 §IV.B: "the
    /// non-repetitive scan-pattern starting at a random initial state").
    pub fn scan(
        &self,
        scan_end: f64,
        integration_time_s: f64,
        points_per_second: f64,
        rng: &mut ChaCha8Rng,
    ) -> Scan {
        let phases = match self {
            ScanPattern::Rosette { .. } => [rng.random_range(0.0..TAU), rng.random_range(0.0..TAU)],
            ScanPattern::Raster { .. } => [0.0, 0.0],
        };
        Scan::new(
            self.clone(),
            scan_end,
            integration_time_s,
            points_per_second,
            phases,
            0.0,
        )
    }
}

/// The rays of one frame: a pattern evaluated at evenly spaced instants.
#[derive(Debug, Clone, PartialEq)]
pub struct Scan {
    pattern: ScanPattern,
    n_rays: usize,
    scan_start: f64,
    dt: f64,
    phases: [f64; 2],
    pattern_time_offset: f64,
    /// Precomputed `(δ, 2π f1, 2π f2)` of a rosette (rad, rad/s).
    rosette: (f64, f64, f64),
}

impl Scan {
    /// A scan with explicit prism phases (rad) and pattern time offset (s):
    /// ray `i` is taken at pattern time `offset + (i + 1/2) dt`.
    pub fn new(
        pattern: ScanPattern,
        scan_end: f64,
        integration_time_s: f64,
        points_per_second: f64,
        phases: [f64; 2],
        pattern_time_offset: f64,
    ) -> Self {
        let n_rays = pattern
            .ray_count(integration_time_s, points_per_second)
            .max(1.0) as usize;
        let rosette = match pattern {
            ScanPattern::Rosette {
                fov_deg,
                prism_rates_hz,
            } => (
                fov_deg.to_radians() / 4.0,
                TAU * prism_rates_hz[0],
                TAU * prism_rates_hz[1],
            ),
            ScanPattern::Raster { .. } => (0.0, 0.0, 0.0),
        };
        Scan {
            pattern,
            n_rays,
            scan_start: scan_end - integration_time_s,
            dt: integration_time_s / n_rays as f64,
            phases,
            pattern_time_offset,
            rosette,
        }
    }

    /// Number of rays.
    pub fn len(&self) -> usize {
        self.n_rays
    }

    /// True when the scan has no ray (never, by construction).
    pub fn is_empty(&self) -> bool {
        self.n_rays == 0
    }

    /// Start of the scan window (s).
    pub fn scan_start(&self) -> f64 {
        self.scan_start
    }

    /// End of the scan window (s).
    pub fn scan_end(&self) -> f64 {
        self.scan_start + self.dt * self.n_rays as f64
    }

    /// Timestamp of ray `i`: the middle of its slot, inside the window.
    #[inline]
    pub fn time(&self, i: usize) -> f64 {
        self.scan_start + (i as f64 + 0.5) * self.dt
    }

    /// Unit direction of ray `i` in the sensor frame.
    #[inline]
    pub fn direction(&self, i: usize) -> Vector3<f64> {
        match self.pattern {
            ScanPattern::Rosette { .. } => {
                let tau = self.pattern_time_offset + (i as f64 + 0.5) * self.dt;
                let (delta, w1, w2) = self.rosette;
                rosette_direction(delta, w1 * tau + self.phases[0], w2 * tau + self.phases[1])
            }
            ScanPattern::Raster {
                fov_x_deg,
                fov_y_deg,
                step_deg,
            } => {
                let nx = (fov_x_deg / step_deg).round() as usize + 1;
                let (row, col) = (i / nx, i % nx);
                let az = (-0.5 * fov_x_deg + col as f64 * step_deg).to_radians();
                let el = (-0.5 * fov_y_deg + row as f64 * step_deg).to_radians();
                Vector3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos())
            }
        }
    }
}

/// Rays re-synchronised with exact `sin_cos` every this many rays when
/// iterating (the phasor recurrence drifts by ~1e-16 per step).
const RESYNC_RAYS: usize = 1024;

impl Scan {
    /// Every ray in scan order as `(time, direction)`: the same values as
    /// [`Scan::time`] and [`Scan::direction`] up to ~1e-13, but the rosette
    /// prism angles advance by complex multiplication instead of two
    /// `sin_cos` per ray.
    pub fn rays(&self) -> ScanRays<'_> {
        ScanRays {
            scan: self,
            i: 0,
            z: [(1.0, 0.0); 2],
            step: [(1.0, 0.0); 2],
        }
    }
}

/// Iterator over the rays of a [`Scan`] (see [`Scan::rays`]).
#[derive(Debug, Clone)]
pub struct ScanRays<'a> {
    scan: &'a Scan,
    i: usize,
    /// Current prism phasors `(cos a, sin a)`.
    z: [(f64, f64); 2],
    /// Per-ray phasor increments.
    step: [(f64, f64); 2],
}

impl Iterator for ScanRays<'_> {
    type Item = (f64, Vector3<f64>);

    #[inline]
    fn next(&mut self) -> Option<Self::Item> {
        let s = self.scan;
        let i = self.i;
        if i >= s.n_rays {
            return None;
        }
        self.i += 1;
        if !matches!(s.pattern, ScanPattern::Rosette { .. }) {
            return Some((s.time(i), s.direction(i)));
        }
        let (delta, w1, w2) = s.rosette;
        if i.is_multiple_of(RESYNC_RAYS) {
            let tau = s.pattern_time_offset + (i as f64 + 0.5) * s.dt;
            let (s1, c1) = (w1 * tau + s.phases[0]).sin_cos();
            let (s2, c2) = (w2 * tau + s.phases[1]).sin_cos();
            self.z = [(c1, s1), (c2, s2)];
            let (s1, c1) = (w1 * s.dt).sin_cos();
            let (s2, c2) = (w2 * s.dt).sin_cos();
            self.step = [(c1, s1), (c2, s2)];
        } else {
            for (z, st) in self.z.iter_mut().zip(&self.step) {
                *z = (z.0 * st.0 - z.1 * st.1, z.0 * st.1 + z.1 * st.0);
            }
        }
        let [(c1, s1), (c2, s2)] = self.z;
        Some((
            s.time(i),
            deflected_direction(delta * (c1 + c2), delta * (s1 + s2)),
        ))
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.scan.n_rays - self.i;
        (left, Some(left))
    }
}

/// Direction after two prism deflections of `delta` (rad) at prism angles
/// `a1`, `a2`: `ψ = δ (e^{i a1} + e^{i a2})` is the off-boresight angle
/// vector, mapped exactly onto the unit sphere (polar angle `|ψ|`).
#[inline]
fn rosette_direction(delta: f64, a1: f64, a2: f64) -> Vector3<f64> {
    let (s1, c1) = a1.sin_cos();
    let (s2, c2) = a2.sin_cos();
    deflected_direction(delta * (c1 + c2), delta * (s1 + s2))
}

/// The unit vector at polar angle `|(px, py)|` from the boresight, toward
/// the azimuth of `(px, py)`.
#[inline]
fn deflected_direction(px: f64, py: f64) -> Vector3<f64> {
    let theta = (px * px + py * py).sqrt();
    let (st, ct) = theta.sin_cos();
    let sinc = if theta > 1e-12 { st / theta } else { 1.0 };
    Vector3::new(px * sinc, py * sinc, ct)
}

#[cfg(test)]
#[path = "pattern_tests.rs"]
mod tests;
