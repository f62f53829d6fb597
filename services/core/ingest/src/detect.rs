//! Finding the target in a frame without a prediction (before the first
//! acquisition, or after a loss), so that the crop can already remove a
//! test facility's floor and walls (not in the papers, which cropped their
//! facility frames off line: seed 000 §4.1, seed 004 §V;
//! `docs/design/target-detection.md`).
//!
//! Only what the suite knows is used: the target's bounding radius `R`
//! (from its package) and the crop margin. Two steps:
//!
//! 1. **Planes too large to be the target.** RANSAC finds the largest plane
//!    of the frame; the points within `plane_tolerance_m` of it are split
//!    into connected patches (a grid of `R / 4` cells in the plane). A patch
//!    wider than the target's diameter `2 (R + margin)` cannot be part of a
//!    target that fits in its bounding sphere: it is background (a floor, a
//!    wall, a curtain) and is removed. Smaller patches (a solar panel) are
//!    kept and left out of the next search. Up to `max_planes` planes.
//! 2. **The densest sphere of radius `R`** in what is left: mean shift
//!    (the centre moves to the mean of the points within `R` of it) from
//!    the centres of the most populated `R`-cells; the centre holding the
//!    most points wins.
//!
//! The region is then the sphere of radius `crop_radius_factor · R +
//! margin` about that centre, minus the background patches. The centre is
//! that of the returns, nearer the sensor than the centre of mass (only the
//! near side returns), hence the factor.

use crate::background::{BackgroundPlane, Search};
use crate::config::DetectConfig;
use nalgebra::Vector3;
use spacepose_geometry::Point;
use std::collections::HashMap;

/// Fewest points a frame needs for a detection.
pub const MIN_DETECTION_POINTS: usize = 20;

/// Where the target is in a frame without a prediction.
#[derive(Debug, Clone)]
pub struct Detection {
    /// Centre of the densest sphere of radius `R` (sensor frame, m).
    pub centre: Vector3<f64>,
    /// Radius of the region about it (m).
    pub radius_m: f64,
    /// Points within `R` of the centre.
    pub points_in_sphere: usize,
    /// The planes whose large patches were removed.
    pub background: Vec<BackgroundPlane>,
}

impl Detection {
    /// True when `x` lies in the region: in the sphere and on no background
    /// patch.
    #[inline]
    pub fn contains(&self, x: &Vector3<f64>) -> bool {
        (x - self.centre).norm_squared() <= self.radius_m * self.radius_m
            && !self.background.iter().any(|b| b.contains(x))
    }
}

/// Finds the target among `points` (already in the range gate), for a
/// target of bounding radius `radius_m` and a crop margin `margin_m`;
/// `None` with fewer than [`MIN_DETECTION_POINTS`] usable points.
pub fn detect(
    points: &[Point],
    radius_m: f64,
    margin_m: f64,
    config: &DetectConfig,
) -> Option<Detection> {
    let all: Vec<Vector3<f64>> = points
        .iter()
        .filter(|p| p.is_finite())
        .map(Point::position)
        .collect();
    if all.len() < MIN_DETECTION_POINTS {
        return None;
    }
    let mut search = Search::new(&all, radius_m, margin_m, config);
    let background = search.background_planes();
    let rest: Vec<Vector3<f64>> = all
        .iter()
        .filter(|x| !background.iter().any(|b| b.contains(x)))
        .copied()
        .collect();
    if rest.len() < MIN_DETECTION_POINTS {
        return None;
    }
    let (centre, points_in_sphere) = densest_sphere(&rest, radius_m)?;
    Some(Detection {
        centre,
        radius_m: config.crop_radius_factor * radius_m + margin_m,
        points_in_sphere,
        background,
    })
}

/// Seeds of the mean shift: the most populated cells of side `R`.
const SEEDS: usize = 8;

/// The centre of the densest sphere of radius `r` among `points` and the
/// points it holds (mean shift from the centres of the [`SEEDS`] fullest
/// cells of side `r`).
fn densest_sphere(points: &[Vector3<f64>], r: f64) -> Option<(Vector3<f64>, usize)> {
    let grid = Grid::new(points, r);
    let mut seeds: Vec<(CellKey, &Vec<usize>)> = grid.cells.iter().map(|(k, v)| (*k, v)).collect();
    seeds.sort_unstable_by(|a, b| b.1.len().cmp(&a.1.len()).then(a.0.cmp(&b.0)));
    let mut best: Option<(Vector3<f64>, usize)> = None;
    for (_, members) in seeds.into_iter().take(SEEDS) {
        let mut c = members.iter().map(|&i| points[i]).sum::<Vector3<f64>>() / members.len() as f64;
        let mut count = 0;
        for _ in 0..30 {
            let (sum, n) = grid.within(points, &c, r);
            count = n;
            if n == 0 {
                break;
            }
            let next = sum / n as f64;
            let moved = (next - c).norm();
            c = next;
            if moved < 1e-3 * r {
                break;
            }
        }
        let count = grid.within(points, &c, r).1.max(count);
        if best.is_none_or(|(_, k)| count > k) {
            best = Some((c, count));
        }
    }
    best
}

/// A cube of the grid.
type CellKey = (i64, i64, i64);

/// Points binned in cubes of side `r`.
struct Grid {
    r: f64,
    cells: HashMap<CellKey, Vec<usize>>,
}

impl Grid {
    fn new(points: &[Vector3<f64>], r: f64) -> Self {
        let mut cells: HashMap<CellKey, Vec<usize>> = HashMap::new();
        for (i, x) in points.iter().enumerate() {
            cells.entry(Self::key(x, r)).or_default().push(i);
        }
        Self { r, cells }
    }

    fn key(x: &Vector3<f64>, r: f64) -> CellKey {
        let q = x / r;
        (q.x.floor() as i64, q.y.floor() as i64, q.z.floor() as i64)
    }

    /// The sum and count of the points within `r` of `c`.
    fn within(&self, points: &[Vector3<f64>], c: &Vector3<f64>, r: f64) -> (Vector3<f64>, usize) {
        let (i, j, k) = Self::key(c, self.r);
        let mut sum = Vector3::zeros();
        let mut n = 0;
        for di in -1..=1 {
            for dj in -1..=1 {
                for dk in -1..=1 {
                    let Some(members) = self.cells.get(&(i + di, j + dj, k + dk)) else {
                        continue;
                    };
                    for &m in members {
                        if (points[m] - c).norm_squared() <= r * r {
                            sum += points[m];
                            n += 1;
                        }
                    }
                }
            }
        }
        (sum, n)
    }
}

#[cfg(test)]
#[path = "detect_tests.rs"]
mod tests;
