//! The first step of the detection ([`crate::detect`]): the planes of a
//! frame too large to be the target (a floor, a wall, a curtain), found by
//! RANSAC and split into connected patches.

use crate::config::DetectConfig;
use nalgebra::{Vector2, Vector3};
use std::collections::{HashMap, HashSet};

/// A background plane: `n · x = d`, and the grid cells (in its own 2D
/// coordinates) of the patches found too large for the target.
#[derive(Debug, Clone)]
pub struct BackgroundPlane {
    /// Unit normal.
    pub normal: Vector3<f64>,
    /// Offset along the normal (m).
    pub offset_m: f64,
    basis: (Vector3<f64>, Vector3<f64>),
    cell_m: f64,
    tolerance_m: f64,
    cells: HashSet<(i64, i64)>,
}

impl BackgroundPlane {
    /// True when `x` lies on one of the plane's background patches.
    #[inline]
    pub fn contains(&self, x: &Vector3<f64>) -> bool {
        (self.normal.dot(x) - self.offset_m).abs() <= self.tolerance_m
            && self.cells.contains(&self.cell_of(x))
    }

    pub(crate) fn cell_of(&self, x: &Vector3<f64>) -> (i64, i64) {
        let (u, v) = &self.basis;
        let q = Vector2::new(u.dot(x), v.dot(x)) / self.cell_m;
        (q.x.floor() as i64, q.y.floor() as i64)
    }
}

/// The RANSAC search for background planes over a subsample of the frame.
pub(crate) struct Search<'a> {
    all: &'a [Vector3<f64>],
    /// Indices into `all` still searched.
    sample: Vec<usize>,
    radius_m: f64,
    margin_m: f64,
    config: &'a DetectConfig,
    rng: SplitMix,
}

impl<'a> Search<'a> {
    pub(crate) fn new(
        all: &'a [Vector3<f64>],
        radius_m: f64,
        margin_m: f64,
        config: &'a DetectConfig,
    ) -> Self {
        let stride = all.len().div_ceil(config.sample_points.max(1)).max(1);
        Self {
            all,
            sample: (0..all.len()).step_by(stride).collect(),
            radius_m,
            margin_m,
            config,
            rng: SplitMix(0x5eed_0fde_7ec7),
        }
    }

    /// Up to `max_planes` planes, each with its patches too large for the
    /// target; a plane with no such patch is left out of the search.
    pub(crate) fn background_planes(&mut self) -> Vec<BackgroundPlane> {
        let mut found = Vec::new();
        let min_inliers = (self.config.min_plane_fraction * self.sample.len() as f64).max(3.0);
        for _ in 0..self.config.max_planes {
            let Some((normal, offset)) = self.best_plane() else {
                break;
            };
            let tol = self.config.plane_tolerance_m;
            let on = |x: &Vector3<f64>| (normal.dot(x) - offset).abs() <= tol;
            if (self.sample.iter().filter(|&&i| on(&self.all[i])).count() as f64) < min_inliers {
                break;
            }
            // Searched once: its large patches go, its small ones stay in
            // the frame but out of the next search.
            self.sample.retain(|&i| !on(&self.all[i]));
            if let Some(p) = self.large_patches(normal, offset, &found) {
                found.push(p);
            }
        }
        found
    }

    /// The plane with the most sample inliers over `ransac_iterations`
    /// random triples.
    fn best_plane(&mut self) -> Option<(Vector3<f64>, f64)> {
        let n = self.sample.len();
        if n < 3 {
            return None;
        }
        let tol = self.config.plane_tolerance_m;
        let mut best: Option<(usize, Vector3<f64>, f64)> = None;
        for _ in 0..self.config.ransac_iterations {
            let [a, b, c] = [0; 3].map(|_| self.all[self.sample[self.rng.below(n)]]);
            let Some(normal) = (b - a).cross(&(c - a)).try_normalize(1e-9) else {
                continue;
            };
            let offset = normal.dot(&a);
            let count = self
                .sample
                .iter()
                .filter(|&&i| (normal.dot(&self.all[i]) - offset).abs() <= tol)
                .count();
            if best.is_none_or(|(k, _, _)| count > k) {
                best = Some((count, normal, offset));
            }
        }
        best.map(|(_, normal, offset)| (normal, offset))
    }

    /// The plane's connected patches (its points within the tolerance that
    /// are not on the background `found` before, on a grid of `R / 4`
    /// cells) wider than the target's diameter, or `None` when there is none.
    fn large_patches(
        &self,
        normal: Vector3<f64>,
        offset: f64,
        found: &[BackgroundPlane],
    ) -> Option<BackgroundPlane> {
        let mut plane = BackgroundPlane {
            normal,
            offset_m: offset,
            basis: in_plane_basis(&normal),
            cell_m: self.radius_m / 4.0,
            tolerance_m: self.config.plane_tolerance_m,
            cells: HashSet::new(),
        };
        let mut cells: HashMap<(i64, i64), Vec<Vector2<f64>>> = HashMap::new();
        for x in self.all {
            let on = (normal.dot(x) - offset).abs() <= plane.tolerance_m;
            if on && !found.iter().any(|b| b.contains(x)) {
                let (u, v) = &plane.basis;
                cells
                    .entry(plane.cell_of(x))
                    .or_default()
                    .push(Vector2::new(u.dot(x), v.dot(x)));
            }
        }
        let diameter = 2.0 * (self.radius_m + self.margin_m);
        for patch in patches(&cells) {
            let points = patch.iter().flat_map(|c| cells[c].iter());
            if extent(points) > diameter {
                plane.cells.extend(patch);
            }
        }
        (!plane.cells.is_empty()).then_some(plane)
    }
}

/// Two unit vectors completing `n` into an orthonormal basis.
fn in_plane_basis(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let u = n.cross(&helper).normalize();
    (u, n.cross(&u))
}

/// The 8-connected patches of occupied cells.
fn patches(cells: &HashMap<(i64, i64), Vec<Vector2<f64>>>) -> Vec<Vec<(i64, i64)>> {
    let mut seen = HashSet::new();
    let mut out = Vec::new();
    for &start in cells.keys() {
        if !seen.insert(start) {
            continue;
        }
        let mut patch = vec![start];
        let mut k = 0;
        while k < patch.len() {
            let (i, j) = patch[k];
            for (di, dj) in NEIGHBOURS {
                let c = (i + di, j + dj);
                if cells.contains_key(&c) && seen.insert(c) {
                    patch.push(c);
                }
            }
            k += 1;
        }
        out.push(patch);
    }
    out
}

const NEIGHBOURS: [(i64, i64); 8] = [
    (-1, -1),
    (-1, 0),
    (-1, 1),
    (0, -1),
    (0, 1),
    (1, -1),
    (1, 0),
    (1, 1),
];

/// The width of a set of plane points: the largest of their spreads along
/// 8 directions 22.5° apart (at least 98 % of the true diameter).
pub(crate) fn extent<'p>(points: impl Iterator<Item = &'p Vector2<f64>>) -> f64 {
    let dirs: [Vector2<f64>; 8] = std::array::from_fn(|k| {
        let a = k as f64 * std::f64::consts::PI / 8.0;
        Vector2::new(a.cos(), a.sin())
    });
    let mut lo = [f64::INFINITY; 8];
    let mut hi = [f64::NEG_INFINITY; 8];
    for p in points {
        for (k, d) in dirs.iter().enumerate() {
            let s = d.dot(p);
            lo[k] = lo[k].min(s);
            hi[k] = hi[k].max(s);
        }
    }
    (0..8).map(|k| hi[k] - lo[k]).fold(0.0, f64::max)
}

/// A small deterministic generator (SplitMix64): the detection of a frame
/// is the same on every run.
struct SplitMix(u64);

impl SplitMix {
    fn below(&mut self, n: usize) -> usize {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z % n as u64) as usize
    }
}
