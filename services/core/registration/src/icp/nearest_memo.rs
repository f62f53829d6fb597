//! Nearest-point answers remembered across ICP iterations, reused while
//! they provably still hold.
//!
//! Late ICP iterations move every point by far less than the gap between
//! its nearest and second-nearest model points, so most lookups would
//! return the same point again. For a query `q₀` in voxel `V` of the
//! [`PointGrid`], let `d₁` and `d₂` be the distances to the nearest and
//! second-nearest candidates of `V` (the nearest `c₁`). For a later query
//! `q` in the same voxel with `δ = |q − q₀|`, the triangle inequality gives
//! `|q − c₁| ≤ d₁ + δ` and `|q − c| ≥ d₂ − δ` for every other candidate
//! `c`; when `δ < (d₂ − d₁) / 2`, `c₁` is still the strict nearest
//! candidate, and since the candidates of `V` contain the nearest model
//! point of every query of `V` that has one within the grid's distance,
//! the answer is `c₁` if `|q − c₁|` is within the limit and none otherwise:
//! exactly what a scan returns. An empty voxel answers none wherever the
//! query is in it. Otherwise the voxel is scanned and the memo re-anchored
//! at `q`.

use super::point_grid::PointGrid;
use nalgebra::Vector3;

/// Voxel value of a memo that holds nothing yet.
const UNSET: u32 = u32::MAX;
/// Voxel value of a memo anchored outside the grid.
const OUTSIDE: u32 = u32::MAX - 1;

/// What one query point remembers of its last voxel scan, in 32 bytes (a
/// frame's memos stay in cache).
#[derive(Debug, Clone, Copy)]
pub(crate) struct NearestMemo {
    /// Query position of the last scan, rounded to f32 (target body
    /// frame, m); the rounding is taken off `reach2_m2`.
    anchor: [f32; 3],
    /// The nearest candidate found by that scan (candidates are f32
    /// exact); NaN when the voxel is empty or outside the grid.
    nearest: [f32; 3],
    /// The voxel of the anchor ([`UNSET`], [`OUTSIDE`] or an index).
    voxel: u32,
    /// Squared distance the query may move from `anchor` with the same
    /// answer: `((d₂ − d₁) / 2 − rounding)²`, rounded down; negative when
    /// it may not move at all (m²).
    reach2_m2: f32,
}

impl Default for NearestMemo {
    fn default() -> Self {
        Self {
            anchor: [0.0; 3],
            nearest: [f32::NAN; 3],
            voxel: UNSET,
            reach2_m2: -1.0,
        }
    }
}

/// Scans and memo reuses, for the lookup statistics of tests.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct MemoCounts {
    /// Voxel scans.
    pub scans: usize,
    /// Answers from a memo.
    pub reused: usize,
}

impl PointGrid {
    /// The nearest model point to `q` within `max2` (squared, at most the
    /// grid's `max_distance²`) and its squared distance, as
    /// [`PointGrid::nearest_within`] answers it, reusing `memo` when it
    /// provably holds and refreshing it otherwise.
    #[inline]
    pub(crate) fn nearest_within_memo(
        &self,
        q: &Vector3<f64>,
        max2: f64,
        memo: &mut NearestMemo,
        counts: &mut MemoCounts,
    ) -> Option<(Vector3<f64>, f64)> {
        // Grids are far below 2³² voxels (`MAX_GRID_VOXELS`).
        let voxel = self.voxel_of(q).map_or(OUTSIDE, |v| v as u32);
        if voxel == memo.voxel
            && (widen(memo.anchor) - q).norm_squared() < f64::from(memo.reach2_m2)
        {
            counts.reused += 1;
        } else {
            counts.scans += usize::from(voxel != OUTSIDE);
            *memo = self.anchor_memo(q, voxel);
        }
        if memo.nearest[0].is_nan() {
            return None;
        }
        let p = widen(memo.nearest);
        let d2 = (p - q).norm_squared();
        (d2 <= max2).then_some((p, d2))
    }

    /// Scans `voxel` for `q` and returns the memo anchored there.
    fn anchor_memo(&self, q: &Vector3<f64>, voxel: u32) -> NearestMemo {
        let anchor = [q.x as f32, q.y as f32, q.z as f32];
        let rounding = (widen(anchor) - q).norm();
        let (nearest, gap) = if voxel == OUTSIDE {
            (None, f64::INFINITY)
        } else {
            let (nearest, d1_2, d2_2) = self.nearest_two(voxel as usize, q);
            (nearest, 0.5 * (d2_2.sqrt() - d1_2.sqrt()))
        };
        // An empty voxel (or outside) answers none anywhere in it.
        let gap = if nearest.is_none() {
            f64::INFINITY
        } else {
            gap
        };
        // Shrunk well beyond the rounding of the distances above.
        let reach = gap * (1.0 - 1e-9) - 1e-12 - rounding;
        NearestMemo {
            anchor,
            nearest: nearest.map_or([f32::NAN; 3], |p| [p.x as f32, p.y as f32, p.z as f32]),
            voxel,
            reach2_m2: if reach > 0.0 {
                (reach * reach * (1.0 - 1e-6)) as f32
            } else {
                -1.0
            },
        }
    }
}

/// An f32 triple as a vector (exactly).
#[inline]
fn widen(v: [f32; 3]) -> Vector3<f64> {
    Vector3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]))
}
