//! Translation voting: where a template best overlaps the sensed cloud
//! (not in seed 002).
//!
//! Seed 002 places a template by centroid alignment, which assumes that the
//! sensor and the template show the same part of the target. At 20 m the
//! raster's field of view clips ENVISAT, and a grid attitude up to ~26°
//! from the truth shows other parts than the sensor saw, so the aligned
//! origin is often metres off (tuning seed 3 at 20 m, the grid attitude
//! nearest the truth: 22 of 50 starts more than 1 m off, 8 refinements
//! failed, against 2 from the true position).
//!
//! Every pair of a sensed point `p` and a template point `q` votes for the
//! translation `p − q`; the translation that superposes the largest common
//! structure collects the most votes. The votes within reach go into a
//! dense histogram of `bin` edges, smoothed over 3×3×3 bins (a 30°
//! attitude error smears them), and the smoothed mode is refined by a few
//! mean-shift steps (the mean of the votes within ±1 bin).

use nalgebra::Vector3;

/// Mean-shift steps refining the histogram's mode (window ±1 bin).
const MEAN_SHIFT_STEPS: usize = 5;

/// Reusable buffers of [`vote_translation`].
#[derive(Debug, Default)]
pub struct VoteScratch {
    votes: Vec<Vector3<f64>>,
    hist: Vec<u32>,
    smooth: Vec<u32>,
    near: Vec<Vector3<f64>>,
}

/// The translation (m) to add to `template` to overlap `sensed` the most,
/// from at most `max_points` evenly strided points of each, on bins of
/// `bin_m`, among translations within `reach_m` of zero on every axis
/// (votes beyond are dropped: the histogram stays small, and a
/// re-centred template is never farther from the truth than the target's
/// size). `None` when either set is empty, no vote falls within reach, or
/// `bin_m` or `reach_m` is not positive.
pub fn vote_translation(
    sensed: &[Vector3<f64>],
    template: &[Vector3<f64>],
    (bin_m, reach_m): (f64, f64),
    max_points: usize,
    scratch: &mut VoteScratch,
) -> Option<Vector3<f64>> {
    let positive = |v: f64| v.is_finite() && v > 0.0;
    if sensed.is_empty() || template.is_empty() || !positive(bin_m) || !positive(reach_m) {
        return None;
    }
    let stride = |n: usize| n.div_ceil(max_points.max(1)).max(1);
    let votes = &mut scratch.votes;
    votes.clear();
    for p in sensed.iter().step_by(stride(sensed.len())) {
        for q in template.iter().step_by(stride(template.len())) {
            let v = p - q;
            if v.amax() <= reach_m {
                votes.push(v);
            }
        }
    }
    let half = (reach_m / bin_m).ceil() as usize;
    let d = 2 * half + 1;
    let lo = Vector3::repeat(-(half as f64 + 0.5) * bin_m);
    let index = |v: &Vector3<f64>| {
        let c = ((v - lo) / bin_m).map(|c| (c as usize).min(d - 1));
        (c.x * d + c.y) * d + c.z
    };
    scratch.hist.clear();
    scratch.hist.resize(d * d * d, 0);
    for v in votes.iter() {
        scratch.hist[index(v)] += 1;
    }
    box_filter(&mut scratch.hist, &mut scratch.smooth, [d, d, d]);
    let (mode, &n) = scratch
        .hist
        .iter()
        .enumerate()
        .max_by_key(|&(i, n)| (*n, std::cmp::Reverse(i)))?;
    if n == 0 {
        return None;
    }
    let (x, y, z) = (mode / (d * d), (mode / d) % d, mode % d);
    let start = lo + Vector3::new(x as f64 + 0.5, y as f64 + 0.5, z as f64 + 0.5) * bin_m;
    Some(mean_shift(votes, start, bin_m, &mut scratch.near))
}

/// Mean shift from `start` (see [`MEAN_SHIFT_STEPS`]): each step moves to
/// the mean of the votes within ±`bin_m` (every axis), from the bin centre:
/// a window centred off the peak of a smeared (planar) vote cloud would
/// bias the mean. The steps scan only the votes within ±3 bins of `start`
/// (kept in `near`, in their order) while the window stays within ±1.9
/// bins of it, where it cannot reach any other vote; the result is that of
/// scanning every vote.
fn mean_shift(
    votes: &[Vector3<f64>],
    start: Vector3<f64>,
    bin_m: f64,
    near: &mut Vec<Vector3<f64>>,
) -> Vector3<f64> {
    near.clear();
    near.extend(votes.iter().filter(|v| (*v - start).amax() <= 3.0 * bin_m));
    let mut centre = start;
    for _ in 0..MEAN_SHIFT_STEPS {
        let pool = if (centre - start).amax() <= 1.9 * bin_m {
            &near[..]
        } else {
            votes
        };
        let (mut sum, mut count) = (Vector3::zeros(), 0usize);
        for v in pool.iter().filter(|v| (*v - centre).amax() <= bin_m) {
            sum += v;
            count += 1;
        }
        if count == 0 {
            break;
        }
        centre = sum / count as f64;
    }
    centre
}

/// 3×3×3 box sum of `hist` (row-major `dims`) in place, as three
/// separable passes through `tmp`: along the two outer axes whole slabs
/// (contiguous runs) are added, along the inner axis each row is summed
/// with its shifted copies.
fn box_filter(hist: &mut Vec<u32>, tmp: &mut Vec<u32>, dims: [usize; 3]) {
    for (s, d) in [(dims[1] * dims[2], dims[0]), (dims[2], dims[1])] {
        std::mem::swap(hist, tmp);
        hist.clear();
        hist.resize(tmp.len(), 0);
        // Blocks of `d` slabs of `s` entries (`d` along this axis).
        for (out, src) in hist.chunks_exact_mut(s * d).zip(tmp.chunks_exact(s * d)) {
            for c in 0..d {
                let slab = &mut out[c * s..(c + 1) * s];
                let lo = c.saturating_sub(1) * s;
                let hi = (c + 2).min(d) * s;
                for k in (lo..hi).step_by(s) {
                    for (o, v) in slab.iter_mut().zip(&src[k..k + s]) {
                        *o += v;
                    }
                }
            }
        }
    }
    std::mem::swap(hist, tmp);
    let d = dims[2];
    for (out, src) in hist.chunks_exact_mut(d).zip(tmp.chunks_exact(d)) {
        for (c, o) in out.iter_mut().enumerate() {
            *o = src[c.saturating_sub(1)..(c + 2).min(d)].iter().sum();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 m cube's faces (the bus) and a 12 m × 4 m plate beside it
    /// (the solar array), at 20 cm spacing.
    fn satellite() -> Vec<Vector3<f64>> {
        let mut pts = Vec::new();
        for i in 0..=10 {
            for j in 0..=10 {
                let (a, b) = (f64::from(i) * 0.2, f64::from(j) * 0.2);
                pts.push(Vector3::new(a, b, 0.0));
                pts.push(Vector3::new(a, 0.0, b));
                pts.push(Vector3::new(0.0, a, b));
            }
        }
        for i in 0..60 {
            for j in 0..20 {
                pts.push(Vector3::new(
                    2.5 + f64::from(i) * 0.2,
                    f64::from(j) * 0.2 - 1.0,
                    1.0,
                ));
            }
        }
        pts
    }

    #[test]
    fn finds_the_overlap_where_centroid_alignment_is_metres_off() {
        let model = satellite();
        let shift = Vector3::new(10.0, -3.0, 20.0);
        // The sensor saw only the bus (the array clipped away).
        let sensed: Vec<Vector3<f64>> = model
            .iter()
            .filter(|p| p.x <= 2.0)
            .map(|p| p + shift)
            .collect();
        let mean = |v: &[Vector3<f64>]| v.iter().sum::<Vector3<f64>>() / v.len() as f64;
        let by_centroid = mean(&sensed) - mean(&model);
        assert!((by_centroid - shift).norm() > 3.0, "{by_centroid}");
        let mut scratch = VoteScratch::default();
        let t = vote_translation(&sensed, &model, (1.0, 30.0), 400, &mut scratch).expect("votes");
        assert!((t - shift).norm() < 0.3, "{t} vs {shift}");
    }

    #[test]
    fn empty_input_or_bad_bin_gives_none() {
        let p = [Vector3::new(1.0, 2.0, 3.0)];
        let mut s = VoteScratch::default();
        let b = (1.0, 10.0);
        assert!(vote_translation(&[], &p, b, 100, &mut s).is_none());
        assert!(vote_translation(&p, &[], b, 100, &mut s).is_none());
        assert!(vote_translation(&p, &p, (f64::NAN, 10.0), 100, &mut s).is_none());
        assert!(vote_translation(&p, &p, (0.0, 10.0), 100, &mut s).is_none());
        assert!(vote_translation(&p, &p, (1.0, f64::NAN), 100, &mut s).is_none());
        // Out of reach.
        assert!(vote_translation(&p, &[Vector3::zeros()], (1.0, 2.0), 100, &mut s).is_none());
        let t = vote_translation(&p, &[Vector3::zeros()], b, 100, &mut s).expect("one vote");
        assert!((t - p[0]).norm() < 1e-12);
    }

    /// The 3×3×3 sum of `hist` at every bin, by its definition.
    fn naive_box(hist: &[u32], [a, b, c]: [usize; 3]) -> Vec<u32> {
        let at = |x: usize, y: usize, z: usize| hist[(x * b + y) * c + z];
        let near = |i: usize, n: usize| i.saturating_sub(1)..(i + 2).min(n);
        let mut out = Vec::with_capacity(hist.len());
        for x in 0..a {
            for y in 0..b {
                for z in 0..c {
                    let mut sum = 0;
                    for i in near(x, a) {
                        for j in near(y, b) {
                            sum += near(z, c).map(|k| at(i, j, k)).sum::<u32>();
                        }
                    }
                    out.push(sum);
                }
            }
        }
        out
    }

    #[test]
    fn box_filter_matches_the_definition() {
        let mut seed = 7u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 33) as u32 % 5
        };
        let mut tmp = Vec::new();
        for dims in [[1, 1, 1], [2, 3, 4], [5, 1, 3], [7, 6, 5], [4, 4, 1]] {
            let mut h: Vec<u32> = (0..dims.iter().product()).map(|_| next()).collect();
            let expected = naive_box(&h, dims);
            box_filter(&mut h, &mut tmp, dims);
            assert_eq!(h, expected, "{dims:?}");
        }
    }

    /// Mean shift by its definition: every step scans every vote.
    fn naive_mean_shift(
        votes: &[Vector3<f64>],
        mut centre: Vector3<f64>,
        bin: f64,
    ) -> Vector3<f64> {
        for _ in 0..MEAN_SHIFT_STEPS {
            let inside: Vec<_> = votes
                .iter()
                .filter(|v| (*v - centre).amax() <= bin)
                .collect();
            if inside.is_empty() {
                break;
            }
            centre = inside.iter().copied().sum::<Vector3<f64>>() / inside.len() as f64;
        }
        centre
    }

    #[test]
    fn mean_shift_matches_scanning_every_vote() {
        let model = satellite();
        let mut near = Vec::new();
        // Votes of the bus against the whole model, and starts from the
        // right bin to several bins away (the window then leaves the pool).
        let sensed: Vec<_> = model.iter().filter(|p| p.x <= 2.0).step_by(3).collect();
        let votes: Vec<Vector3<f64>> = sensed
            .iter()
            .flat_map(|p| model.iter().step_by(7).map(move |q| *p - q))
            .collect();
        for start in [
            Vector3::zeros(),
            Vector3::new(0.5, -0.5, 0.2),
            Vector3::new(2.5, 0.0, -1.0),
            Vector3::new(6.0, 1.0, 0.0),
        ] {
            for bin in [0.5, 1.0] {
                let fast = mean_shift(&votes, start, bin, &mut near);
                assert_eq!(
                    fast,
                    naive_mean_shift(&votes, start, bin),
                    "{start} bin {bin}"
                );
            }
        }
    }

    #[test]
    fn box_filter_sums_the_neighbourhood() {
        let dims = [3, 3, 3];
        let mut h = vec![0u32; 27];
        h[13] = 1; // the centre
        let mut tmp = Vec::new();
        box_filter(&mut h, &mut tmp, dims);
        assert!(h.iter().all(|&v| v == 1), "{h:?}");
        let mut h = vec![0u32; 27];
        h[0] = 1; // a corner reaches its 2×2×2 neighbourhood only
        box_filter(&mut h, &mut tmp, dims);
        assert_eq!(h.iter().sum::<u32>(), 8);
    }
}
