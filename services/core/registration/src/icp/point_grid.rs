//! An exact nearest-model-point lookup grid for ICP: the counterpart over
//! the model *points* of the NDT map's grid over cell means
//! (`ndt_map/lookup.rs`), built with a kd-tree instead of a scan over every
//! point so that tens of thousands of points build in a fraction of a
//! second.
//!
//! Each voxel `V` (centre `c`, half-diagonal `r`) stores the model points
//! that can be the nearest one, within `d_max`, of some query in `V`:
//! - let `d_c` be the distance from `c` to its nearest model point. If
//!   `d_c - r > d_max`, no query of `V` has a point within `d_max`: the
//!   list is empty;
//! - otherwise, the nearest point `p*` of any `q ∈ V` satisfies
//!   `|q - p*| ≤ |q - c| + d_c ≤ r + d_c`, hence `|c - p*| ≤ d_c + 2r`; and
//!   when `|q - p*| ≤ d_max`, also `|c - p*| ≤ d_max + r`. Every point within
//!   `min(d_c + 2r, d_max + r)` of `c` is gathered (a kd-tree radius query);
//! - a gathered point `k` is dropped when a kept point `j` is at least as
//!   near as `k` to every `q ∈ V`, tested exactly on the box:
//!   `max_{q∈V} |q - j|² - |q - k|² = |a_j|² - |a_k|² + 2e ‖a_j - a_k‖₁ ≤ 0`
//!   with `a = p - c` and `e` the half edge. The points are visited by
//!   increasing `|p - c|`, which a dominating point never exceeds, and
//!   domination is transitive, so testing against the kept ones suffices.
//!
//! The model points must be exactly representable in f32 (the candidates
//! are stored so); distances are computed in f64.
//!
//! The search over a voxel's list is therefore exact (up to the choice
//! among equidistant points) for every query whose nearest point is within
//! `d_max`; beyond the grid no point is within `d_max`.

use crate::kdtree::Tree3;
use crate::voxel_box::VoxelBox;
use kiddo::SquaredEuclidean;
use nalgebra::Vector3;

/// A candidate model point: its coordinates, stored in f32 (the model
/// points are f32-exact, see `IcpModel`), so a lookup reads one contiguous
/// run of 12-byte entries.
type Candidate = [f32; 3];

/// The lookup grid (dense voxel array of candidate lists in CSR form).
#[derive(Debug, Clone)]
pub(crate) struct PointGrid {
    origin: [f64; 3],
    resolution: f64,
    inv_resolution: f64,
    dims: [u32; 3],
    /// Distance the candidate lists are exact for (m).
    pub max_distance: f64,
    offsets: Vec<u32>,
    candidates: Vec<Candidate>,
}

/// Buffers reused across voxels while building.
#[derive(Default)]
struct Scratch {
    /// `(|a|², point index, a = p - c)` of the gathered points.
    gathered: Vec<(f64, u32, Vector3<f64>)>,
    /// `a` of the points kept so far.
    kept: Vec<Vector3<f64>>,
}

/// Relative widening of the voxel used when building, so that a query
/// rounded into a neighbouring voxel is still served exactly.
const BOX_MARGIN: f64 = 1e-9;

impl PointGrid {
    /// Builds the grid over `points` (finite, not empty) with voxel edge
    /// `resolution`, coarsened until the grid holds at most `max_voxels`.
    pub(crate) fn build(
        points: &[Vector3<f64>],
        tree: &Tree3,
        max_distance: f64,
        resolution: f64,
        max_voxels: usize,
    ) -> Self {
        let VoxelBox {
            origin: lo,
            resolution: h,
            dims,
        } = VoxelBox::fit(points, max_distance, resolution, max_voxels);
        let mut grid = Self {
            origin: [lo.x, lo.y, lo.z],
            resolution: h,
            inv_resolution: 1.0 / h,
            dims,
            max_distance,
            offsets: Vec::new(),
            candidates: Vec::new(),
        };
        grid.fill(points, tree);
        grid
    }

    /// Computes every voxel's candidate list.
    fn fill(&mut self, points: &[Vector3<f64>], tree: &Tree3) {
        let h = self.resolution;
        let e = 0.5 * h * (1.0 + BOX_MARGIN);
        let reach = ((self.max_distance + e * 3f64.sqrt()) / h).ceil() as usize + 1;
        let near = self.near_mask(points, reach);
        let mut offsets = Vec::with_capacity(near.len() + 1);
        offsets.push(0u32);
        let mut scratch = Scratch::default();
        let mut v = 0;
        for iz in 0..self.dims[2] {
            for iy in 0..self.dims[1] {
                for ix in 0..self.dims[0] {
                    if near[v] {
                        let c = Vector3::new(ix, iy, iz)
                            .map(|i| f64::from(i) + 0.5)
                            .component_mul(&Vector3::repeat(h))
                            + Vector3::from(self.origin);
                        self.push_candidates(&c, e, points, tree, &mut scratch);
                    }
                    v += 1;
                    offsets.push(self.candidates.len() as u32);
                }
            }
        }
        self.offsets = offsets;
    }

    /// Appends the candidates of the voxel of centre `c` and half edge `e`
    /// (see the module documentation).
    fn push_candidates(
        &mut self,
        c: &Vector3<f64>,
        e: f64,
        points: &[Vector3<f64>],
        tree: &Tree3,
        scratch: &mut Scratch,
    ) {
        let r = e * 3f64.sqrt();
        let query = [c.x, c.y, c.z];
        let d_c = tree
            .query(&query)
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute()
            .distance
            .sqrt();
        if d_c - r > self.max_distance {
            return;
        }
        let radius = (d_c + 2.0 * r).min(self.max_distance + r) * (1.0 + 1e-9);
        let gathered = &mut scratch.gathered;
        gathered.clear();
        for hit in tree
            .query(&query)
            .within::<SquaredEuclidean<f64>>(radius * radius)
            .unsorted()
            .execute()
        {
            let a = points[hit.item as usize] - c;
            gathered.push((a.norm_squared(), hit.item, a));
        }
        gathered.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let kept = &mut scratch.kept;
        kept.clear();
        for &(ak2, k, ak) in gathered.iter() {
            // max over the box of |q - j|² - |q - k|², ≤ 0: j dominates k.
            let dominated = kept
                .iter()
                .any(|aj| aj.norm_squared() - ak2 + 2.0 * e * (aj - ak).abs().sum() <= 0.0);
            if !dominated {
                kept.push(ak);
                let p = &points[k as usize];
                self.candidates.push([p.x as f32, p.y as f32, p.z as f32]);
            }
        }
    }

    /// Voxels within `reach` voxels (along every axis) of a voxel holding a
    /// model point; every other voxel is farther than `d_max + r` from all
    /// points when `reach ≥ ⌈(d_max + r)/h⌉ + 1`, so its list is empty.
    fn near_mask(&self, points: &[Vector3<f64>], reach: usize) -> Vec<bool> {
        let dims = self.dims.map(|d| d as usize);
        let mut mask = vec![false; dims.iter().product()];
        for p in points {
            let i = |a: usize| {
                (((p[a] - self.origin[a]) * self.inv_resolution) as usize).min(dims[a] - 1)
            };
            mask[(i(2) * dims[1] + i(1)) * dims[0] + i(0)] = true;
        }
        // Separable dilation, one axis at a time.
        let strides = [1, dims[0], dims[0] * dims[1]];
        for axis in 0..3 {
            let (len, stride) = (dims[axis], strides[axis]);
            let mut line = vec![false; len];
            for start in 0..mask.len() {
                if (start / stride) % len != 0 {
                    continue; // not the first voxel of a line along `axis`
                }
                for (k, l) in line.iter_mut().enumerate() {
                    *l = mask[start + k * stride];
                }
                let mut last_set: Option<usize> = None;
                let mut next_set = line.iter().position(|&b| b);
                for k in 0..len {
                    if line[k] {
                        last_set = Some(k);
                        next_set = line[k + 1..].iter().position(|&b| b).map(|j| k + 1 + j);
                    }
                    let near_before = last_set.is_some_and(|j| k - j <= reach);
                    let near_after = next_set.is_some_and(|j| j >= k && j - k <= reach);
                    mask[start + k * stride] = near_before || near_after;
                }
            }
        }
        mask
    }

    /// The index of the voxel containing `q` (`None` outside the grid or
    /// for a non-finite `q`).
    #[inline]
    pub(crate) fn voxel_of(&self, q: &Vector3<f64>) -> Option<usize> {
        let fx = (q.x - self.origin[0]) * self.inv_resolution;
        let fy = (q.y - self.origin[1]) * self.inv_resolution;
        let fz = (q.z - self.origin[2]) * self.inv_resolution;
        // Negated comparisons so NaN falls outside.
        if !(fx >= 0.0 && fy >= 0.0 && fz >= 0.0) {
            return None;
        }
        let (ix, iy, iz) = (fx as u64, fy as u64, fz as u64);
        let [nx, ny, nz] = self.dims.map(u64::from);
        if ix >= nx || iy >= ny || iz >= nz {
            return None;
        }
        Some(((iz * ny + iy) * nx + ix) as usize)
    }

    /// The candidates of voxel `v`.
    #[inline]
    fn candidates_of(&self, v: usize) -> &[Candidate] {
        &self.candidates[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }

    /// The nearest model point to `q` and the squared distance, if that
    /// distance is at most `max2` (which must not exceed `max_distance²`).
    #[inline]
    pub(crate) fn nearest_within(
        &self,
        q: &Vector3<f64>,
        max2: f64,
    ) -> Option<(Vector3<f64>, f64)> {
        let v = self.voxel_of(q)?;
        let mut best = (None, max2);
        for c in self.candidates_of(v) {
            let p = Vector3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2]));
            let d2 = (p - q).norm_squared();
            if d2 <= best.1 {
                best = (Some(p), d2);
            }
        }
        best.0.map(|p| (p, best.1))
    }

    /// Scans voxel `v` for `q` (in `v`): the nearest candidate (the last
    /// of equals, as [`PointGrid::nearest_within`]) with its squared
    /// distance, and the second smallest squared distance (infinite with
    /// fewer than two candidates; equal to the first on a tie).
    #[inline]
    pub(crate) fn nearest_two(
        &self,
        v: usize,
        q: &Vector3<f64>,
    ) -> (Option<Vector3<f64>>, f64, f64) {
        let (mut best, mut d1, mut d2nd) = (None, f64::INFINITY, f64::INFINITY);
        for c in self.candidates_of(v) {
            let p = Vector3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2]));
            let d2 = (p - q).norm_squared();
            if d2 <= d1 {
                d2nd = d1;
                (best, d1) = (Some(p), d2);
            } else if d2 < d2nd {
                d2nd = d2;
            }
        }
        (best, d1, d2nd)
    }

    /// Voxel edge (m), dimensions, candidates in total and non-empty voxels.
    pub(crate) fn stats(&self) -> (f64, [u32; 3], usize, usize) {
        let non_empty = self.offsets.windows(2).filter(|w| w[1] > w[0]).count();
        (self.resolution, self.dims, self.candidates.len(), non_empty)
    }
}
