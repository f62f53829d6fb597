//! A precomputed voxel grid answering "which cell mean is nearest to `q`,
//! if any lies within `d_max`" exactly, with a handful of distance tests.
//!
//! Each voxel `V` stores the cells that can be the nearest one within
//! `d_max` for *some* query in `V`:
//! - cell `k` is a candidate only if `mindist(μ_k, V) ≤ d_max`;
//! - let `D = min_j maxdist(μ_j, V)` over those candidates: any query in `V`
//!   has a mean within `D`, so cell `k` with `mindist(μ_k, V) > D` can never
//!   be the nearest and is dropped.
//!
//! If the true nearest mean `μ_j` of a query `q ∈ V` is within `d_max`, then
//! `mindist(μ_j, V) ≤ |q - μ_j| ≤ d_max` and `≤ |q - μ_k| ≤ maxdist(μ_k, V)`
//! for every `k`, so `j` is kept: the search over the candidates is exact.

use crate::voxel_box::VoxelBox;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The lookup grid (dense voxel array of candidate lists in CSR form).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct LookupGrid {
    /// Corner of voxel (0, 0, 0).
    pub origin: [f64; 3],
    /// Voxel edge (m).
    pub resolution: f64,
    /// Number of voxels along x, y, z.
    pub dims: [u32; 3],
    /// Distance the candidate lists are exact for (m).
    pub max_distance: f64,
    /// `candidates[offsets[v]..offsets[v + 1]]` are the cells of voxel `v`.
    pub offsets: Vec<u32>,
    /// Concatenated candidate cell indices.
    pub candidates: Vec<u32>,
    /// `candidates` with each cell's mean copied alongside, so a lookup
    /// reads one contiguous run (rebuilt by [`LookupGrid::pack`], not
    /// stored).
    #[serde(skip)]
    pub packed: Vec<Candidate>,
}

/// A candidate cell and its mean.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Candidate {
    /// Mean of the cell.
    pub mean: [f64; 3],
    /// Index of the cell.
    pub cell: u32,
}

/// Squared distance from `p` to the box `[lo, lo + h]³` (0 inside), and to
/// its farthest corner.
#[inline]
fn box_distances2(p: &[f64; 3], lo: &[f64; 3], h: f64) -> (f64, f64) {
    let (mut min2, mut max2) = (0.0, 0.0);
    for a in 0..3 {
        let (l, u) = (lo[a], lo[a] + h);
        let below = (l - p[a]).max(0.0);
        let above = (p[a] - u).max(0.0);
        let m = below.max(above);
        min2 += m * m;
        let far = (p[a] - l).abs().max((u - p[a]).abs());
        max2 += far * far;
    }
    (min2, max2)
}

impl LookupGrid {
    /// Builds the grid for `means`, coarsening `resolution` until the grid
    /// holds at most `max_voxels` voxels. `means` must not be empty and must
    /// be finite.
    pub(crate) fn build(
        means: &[Vector3<f64>],
        max_distance: f64,
        resolution: f64,
        max_voxels: usize,
    ) -> Self {
        let VoxelBox {
            origin: lo,
            resolution: h,
            dims,
        } = VoxelBox::fit(means, max_distance, resolution, max_voxels);
        let mut grid = Self {
            origin: [lo.x, lo.y, lo.z],
            resolution: h,
            dims,
            max_distance,
            offsets: Vec::new(),
            candidates: Vec::new(),
            packed: Vec::new(),
        };
        grid.fill(means);
        grid.prune_dominated(means);
        grid.pack(means);
        grid
    }

    fn voxel_count(&self) -> usize {
        self.dims.iter().map(|&d| d as usize).product()
    }

    /// Calls `f(voxel, mindist², maxdist²)` for every voxel within
    /// `max_distance` of `m`.
    fn for_voxels_near(&self, m: &Vector3<f64>, mut f: impl FnMut(usize, f64, f64)) {
        let h = self.resolution;
        let d2max = self.max_distance * self.max_distance;
        let p = [m.x, m.y, m.z];
        let range = |a: usize| {
            let lo = ((p[a] - self.max_distance - self.origin[a]) / h)
                .floor()
                .max(0.0) as u32;
            let hi = ((p[a] + self.max_distance - self.origin[a]) / h).floor() as u32;
            (lo, hi.min(self.dims[a] - 1))
        };
        let (rx, ry, rz) = (range(0), range(1), range(2));
        for iz in rz.0..=rz.1 {
            for iy in ry.0..=ry.1 {
                for ix in rx.0..=rx.1 {
                    let corner = [
                        self.origin[0] + f64::from(ix) * h,
                        self.origin[1] + f64::from(iy) * h,
                        self.origin[2] + f64::from(iz) * h,
                    ];
                    let (min2, max2) = box_distances2(&p, &corner, h);
                    if min2 <= d2max {
                        f(self.index(ix, iy, iz), min2, max2);
                    }
                }
            }
        }
    }

    #[inline]
    fn index(&self, ix: u32, iy: u32, iz: u32) -> usize {
        (iz as usize * self.dims[1] as usize + iy as usize) * self.dims[0] as usize + ix as usize
    }

    /// Fills the candidate lists (three passes over the cells).
    fn fill(&mut self, means: &[Vector3<f64>]) {
        let n = self.voxel_count();
        // Pass 1: D = min over reachable cells of maxdist² (f32, rounded up
        // by a relative margin so the pruning stays conservative).
        let mut bound = vec![f32::INFINITY; n];
        for m in means {
            self.for_voxels_near(m, |v, _, max2| {
                let b = (max2 * (1.0 + 1e-5)) as f32;
                if b < bound[v] {
                    bound[v] = b;
                }
            });
        }
        // Pass 2: count the survivors.
        let mut counts = vec![0u32; n + 1];
        for m in means {
            self.for_voxels_near(m, |v, min2, _| {
                if min2 <= f64::from(bound[v]) {
                    counts[v + 1] += 1;
                }
            });
        }
        for v in 0..n {
            counts[v + 1] += counts[v];
        }
        // Pass 3: fill.
        let mut cursor = counts.clone();
        let mut candidates = vec![0u32; counts[n] as usize];
        for (k, m) in means.iter().enumerate() {
            self.for_voxels_near(m, |v, min2, _| {
                if min2 <= f64::from(bound[v]) {
                    candidates[cursor[v] as usize] = k as u32;
                    cursor[v] += 1;
                }
            });
        }
        self.offsets = counts;
        self.candidates = candidates;
    }

    /// Drops every candidate that another candidate of the same voxel
    /// dominates over the whole voxel: `|q - μ_j| ≤ |q - μ_k|` at the eight
    /// corners, hence (half-spaces being convex) everywhere in the voxel.
    /// Ties (equal at every corner) keep the lower index. Whenever `k` was
    /// the nearest cell within `d_max`, a surviving `j` is at least as near,
    /// so the search stays exact (up to the choice among equidistant cells).
    fn prune_dominated(&mut self, means: &[Vector3<f64>]) {
        let n = self.voxel_count();
        let mut offsets = Vec::with_capacity(n + 1);
        let mut kept = Vec::with_capacity(self.candidates.len());
        offsets.push(0u32);
        let (nx, ny) = (self.dims[0] as usize, self.dims[1] as usize);
        let h = self.resolution;
        for v in 0..n {
            let list = &self.candidates[self.offsets[v] as usize..self.offsets[v + 1] as usize];
            if list.len() > 1 {
                let (ix, iy, iz) = (v % nx, (v / nx) % ny, v / (nx * ny));
                let lo = Vector3::new(
                    self.origin[0] + ix as f64 * h,
                    self.origin[1] + iy as f64 * h,
                    self.origin[2] + iz as f64 * h,
                );
                let corners: [Vector3<f64>; 8] = std::array::from_fn(|c| {
                    lo + Vector3::new(
                        (c & 1) as f64 * h,
                        ((c >> 1) & 1) as f64 * h,
                        ((c >> 2) & 1) as f64 * h,
                    )
                });
                for &k in list {
                    let mk = &means[k as usize];
                    let dominated = list.iter().any(|&j| {
                        if j == k {
                            return false;
                        }
                        let mj = &means[j as usize];
                        let mut strict = false;
                        for q in &corners {
                            let (dj, dk) = ((q - mj).norm_squared(), (q - mk).norm_squared());
                            if dj > dk {
                                return false;
                            }
                            strict |= dj < dk;
                        }
                        strict || j < k
                    });
                    if !dominated {
                        kept.push(k);
                    }
                }
            } else {
                kept.extend_from_slice(list);
            }
            offsets.push(kept.len() as u32);
        }
        self.offsets = offsets;
        self.candidates = kept;
    }

    /// Rebuilds [`LookupGrid::packed`] from the cell means.
    pub(crate) fn pack(&mut self, means: &[Vector3<f64>]) {
        self.packed = self
            .candidates
            .iter()
            .map(|&k| {
                let m = &means[k as usize];
                Candidate {
                    mean: [m.x, m.y, m.z],
                    cell: k,
                }
            })
            .collect();
    }

    /// The candidate cells of the voxel containing `q` (empty outside the
    /// grid or for a non-finite `q`).
    #[inline]
    pub(crate) fn candidates_at(&self, q: &Vector3<f64>) -> &[Candidate] {
        let inv_h = 1.0 / self.resolution;
        let fx = (q.x - self.origin[0]) * inv_h;
        let fy = (q.y - self.origin[1]) * inv_h;
        let fz = (q.z - self.origin[2]) * inv_h;
        // Negated comparisons so NaN falls outside.
        if !(fx >= 0.0 && fy >= 0.0 && fz >= 0.0) {
            return &[];
        }
        let (ix, iy, iz) = (fx as u64, fy as u64, fz as u64);
        if ix >= u64::from(self.dims[0])
            || iy >= u64::from(self.dims[1])
            || iz >= u64::from(self.dims[2])
        {
            return &[];
        }
        let v = self.index(ix as u32, iy as u32, iz as u32);
        &self.packed[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }

    /// Checks the internal consistency of a decoded grid against the number
    /// of cells; returns a description of the first problem found.
    pub(crate) fn check(&self, cells: usize) -> Result<(), String> {
        if !(self.resolution.is_finite() && self.resolution > 0.0 && self.max_distance.is_finite())
            || self.origin.iter().any(|o| !o.is_finite())
            || self.dims.contains(&0)
        {
            return Err("lookup grid geometry".into());
        }
        let n = self
            .dims
            .iter()
            .try_fold(1usize, |acc, &d| acc.checked_mul(d as usize));
        if n.and_then(|n| n.checked_add(1)) != Some(self.offsets.len()) {
            return Err("lookup grid offsets length".into());
        }
        if self.offsets.first() != Some(&0)
            || self.offsets.windows(2).any(|w| w[0] > w[1])
            || self.offsets.last().map(|&l| l as usize) != Some(self.candidates.len())
        {
            return Err("lookup grid offsets".into());
        }
        if self.candidates.iter().any(|&c| c as usize >= cells) {
            return Err("lookup grid candidate out of range".into());
        }
        Ok(())
    }

    /// Mean number of candidates per non-empty voxel, and the number of
    /// non-empty voxels.
    pub(crate) fn occupancy(&self) -> (f64, usize) {
        let non_empty = self.offsets.windows(2).filter(|w| w[1] > w[0]).count();
        (
            self.candidates.len() as f64 / non_empty.max(1) as f64,
            non_empty,
        )
    }
}
