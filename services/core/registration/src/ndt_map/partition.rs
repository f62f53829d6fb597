//! The kd-tree partition of the model cloud (seed 000 §3.1): each cell is
//! split recursively at the median of its widest axis until the minimal
//! cell size is reached.

use nalgebra::Vector3;

/// One leaf of the partition: a range of the permuted index array and the
/// centre of the points' bounding box (the `c` of Eq. 2).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Leaf {
    /// First index into the permutation.
    pub start: usize,
    /// One past the last index into the permutation.
    pub end: usize,
    /// Centre of the axis-aligned bounding box of the leaf's points.
    pub centre: Vector3<f64>,
}

/// Axis-aligned bounding box of `points[idx]` for `idx` in `indices`.
fn bounds(points: &[Vector3<f64>], indices: &[u32]) -> (Vector3<f64>, Vector3<f64>) {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for &i in indices {
        let p = &points[i as usize];
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    (lo, hi)
}

/// Partitions `points` into leaves whose widest extent is at most
/// `min_cell_size` (unless splitting would leave a half with fewer than
/// `min_points` points). Returns the permutation of point indices and the
/// leaves, each a contiguous range of that permutation.
pub(crate) fn partition(
    points: &[Vector3<f64>],
    min_cell_size: f64,
    min_points: usize,
) -> (Vec<u32>, Vec<Leaf>) {
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    let mut leaves = Vec::new();
    // Explicit stack of (start, end) ranges: no recursion depth concerns.
    let mut stack = vec![(0usize, points.len())];
    while let Some((start, end)) = stack.pop() {
        let slice = &mut order[start..end];
        let (lo, hi) = bounds(points, slice);
        let extent = hi - lo;
        let axis = extent.imax();
        let n = end - start;
        if extent[axis] <= min_cell_size || n < 2 * min_points.max(1) {
            leaves.push(Leaf {
                start,
                end,
                centre: (lo + hi) * 0.5,
            });
            continue;
        }
        let mid = n / 2;
        slice.select_nth_unstable_by(mid, |&a, &b| {
            points[a as usize][axis].total_cmp(&points[b as usize][axis])
        });
        stack.push((start + mid, end));
        stack.push((start, start + mid));
    }
    (order, leaves)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leaves_cover_every_point_once_and_respect_the_size() {
        let pts: Vec<Vector3<f64>> = (0..40)
            .flat_map(|i| (0..40).map(move |j| Vector3::new(i as f64 * 0.01, j as f64 * 0.01, 0.0)))
            .collect();
        let (order, leaves) = partition(&pts, 0.075, 3);
        let mut seen = vec![false; pts.len()];
        for leaf in &leaves {
            let idx = &order[leaf.start..leaf.end];
            let (lo, hi) = bounds(&pts, idx);
            assert!((hi - lo).max() <= 0.075 + 1e-12);
            for &i in idx {
                assert!(!seen[i as usize]);
                seen[i as usize] = true;
            }
        }
        assert!(seen.iter().all(|&s| s));
        // 0.39 m square into cells of at most 7.5 cm: at least 6×6 of them.
        assert!(leaves.len() >= 36, "{} leaves", leaves.len());
    }

    #[test]
    fn identical_points_make_one_leaf() {
        let pts = vec![Vector3::new(1.0, 2.0, 3.0); 100];
        let (_, leaves) = partition(&pts, 0.075, 3);
        assert_eq!(leaves.len(), 1);
    }
}
