//! Principal axes of the surface and the candidate rotations they suggest
//! (see the method in [`crate::symmetry`]).

use std::f64::consts::{PI, TAU};

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

use crate::mesh::Mesh;

/// Most vertex directions taken in a degenerate principal plane (each also
/// gives a bisector, so at most twice as many half-turn axes).
const MAX_PLANE_ANGLES: usize = 180;
/// Most farthest-vertex directions taken when all three moments are equal.
const MAX_FARTHEST: usize = 48;
/// Vertices closer than this fraction of `R` to an axis give no direction.
const MIN_OFF_AXIS: f64 = 0.02;
/// Two axes closer than this (sine of their angle) are the same line.
const SAME_LINE: f64 = 1e-9;

/// A candidate rotation: `angle` (rad) about `axis`, through the body origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Candidate {
    /// Unit axis.
    pub(crate) axis: Unit<Vector3<f64>>,
    /// Angle (rad) in (−π, π].
    pub(crate) angle: f64,
}

impl Candidate {
    /// The rotation.
    pub(crate) fn rotation(&self) -> Rotation3<f64> {
        Rotation3::from_axis_angle(&self.axis, self.angle)
    }
}

/// How the principal moments of the surface coincide.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Moments {
    /// Three distinct moments: their axes.
    Distinct([Unit<Vector3<f64>>; 3]),
    /// Two equal moments: the axis of the third.
    Axial(Unit<Vector3<f64>>),
    /// Three moments equal within the gap: no preferred axis, but the
    /// eigenvectors are kept. A body whose axial moment is only close to
    /// its transverse ones (a 3-fold bus about as long as it is wide) has
    /// an exact symmetry axis among them that no farthest vertex points
    /// along.
    Isotropic([Unit<Vector3<f64>>; 3]),
}

/// Second moment `∫ p pᵀ dA` of the surface about the body origin (m⁴): for
/// a triangle of area `A` and vertices `a, b, c`, `A/12 (a aᵀ + b bᵀ + c cᵀ
/// + s sᵀ)` with `s = a + b + c`.
pub(crate) fn second_moment(mesh: &Mesh) -> Matrix3<f64> {
    let v = mesh.vertices();
    mesh.triangles()
        .iter()
        .zip(mesh.face_areas())
        .fold(Matrix3::zeros(), |acc, (t, &area)| {
            let [a, b, c] = t.map(|k| v[k as usize]);
            let s = a + b + c;
            let sum = a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose();
            acc + sum * (area / 12.0)
        })
}

/// Eigen-decomposes `moment` and tells which moments coincide: two are
/// equal when they differ by at most `gap` times the trace.
pub(crate) fn classify_moments(moment: &Matrix3<f64>, gap: f64) -> Moments {
    let eig = moment.symmetric_eigen();
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let l = order.map(|i| eig.eigenvalues[i]);
    let trace = l.iter().map(|x| x.abs()).sum::<f64>();
    let near = |a: f64, b: f64| (b - a).abs() <= gap * trace;
    let axis = |k: usize| Unit::new_normalize(eig.eigenvectors.column(order[k]).into_owned());
    match (near(l[0], l[1]), near(l[1], l[2])) {
        (false, false) => Moments::Distinct([axis(0), axis(1), axis(2)]),
        (true, false) => Moments::Axial(axis(2)),
        (false, true) => Moments::Axial(axis(0)),
        (true, true) => Moments::Isotropic([axis(0), axis(1), axis(2)]),
    }
}

/// The angles `2πk/n` for `n = 2..=max_order`, `k` prime to `n`, in
/// (−π, π], by increasing `n`: each rotation of order at most `max_order`
/// about an axis appears once.
pub(crate) fn n_fold_angles(max_order: u32) -> Vec<f64> {
    let gcd = |mut a: u32, mut b: u32| {
        while b != 0 {
            (a, b) = (b, a % b);
        }
        a
    };
    let mut out = Vec::new();
    for n in 2..=max_order {
        for k in (1..n).filter(|&k| gcd(k, n) == 1) {
            let a = TAU * f64::from(k) / f64::from(n);
            out.push(if a > PI { a - TAU } else { a });
        }
    }
    out
}

/// The candidate rotations of `mesh` (bounding radius `radius`), given how
/// its moments coincide; `level` (m) groups vertices at equal distances.
/// Axes that may carry any order get every angle of [`n_fold_angles`];
/// axes that can only carry a half-turn get π alone.
pub(crate) fn candidate_rotations(
    mesh: &Mesh,
    moments: &Moments,
    max_order: u32,
    radius: f64,
    level: f64,
) -> Vec<Candidate> {
    let (any_order, half_turn) = match moments {
        Moments::Distinct(axes) => (axes.to_vec(), Vec::new()),
        Moments::Axial(axis) => (
            vec![*axis],
            in_plane_axes(mesh.vertices(), axis, radius, level),
        ),
        Moments::Isotropic(axes) => {
            let far = farthest_directions(mesh.vertices(), radius, level);
            let sums = pair_sums(&far);
            (axes.iter().copied().chain(far).collect(), sums)
        }
    };
    let any_order = distinct_lines(any_order, &[]);
    let half_turn = distinct_lines(half_turn, &any_order);
    let angles = n_fold_angles(max_order);
    let mut out: Vec<Candidate> = any_order
        .iter()
        .flat_map(|&axis| angles.iter().map(move |&angle| Candidate { axis, angle }))
        .collect();
    out.extend(
        half_turn
            .into_iter()
            .map(|axis| Candidate { axis, angle: PI }),
    );
    out
}

/// Axis lines of `axes` (a line and its opposite are one), dropping those
/// already in `known`, first occurrence kept.
fn distinct_lines(
    axes: Vec<Unit<Vector3<f64>>>,
    known: &[Unit<Vector3<f64>>],
) -> Vec<Unit<Vector3<f64>>> {
    let mut out: Vec<Unit<Vector3<f64>>> = Vec::with_capacity(axes.len());
    for a in axes {
        let same = |b: &Unit<Vector3<f64>>| a.cross(b).norm() < SAME_LINE;
        if !known.iter().any(same) && !out.iter().any(same) {
            out.push(a);
        }
    }
    out
}

/// Two unit vectors completing `axis` to a right-handed orthonormal frame.
fn plane_basis(axis: &Unit<Vector3<f64>>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if axis.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let b1 = axis.cross(&helper).normalize();
    let b2 = axis.cross(&b1);
    (b1, b2)
}

/// Half-turn axes perpendicular to `axis` (the unique principal axis).
///
/// A half-turn about a line `u` of the plane acts on the vertices projected
/// on the plane as the mirror across `u`, and keeps each vertex's distance
/// `r` from `axis`. So each level of `r` (vertices within `level` of each
/// other, from the largest `r` down) is a mirror-symmetric set of directions,
/// and `u` either passes through one of them or bisects two that are
/// angular neighbours. The outermost level is made of surface points farthest
/// from the axis, which are always vertices; inner levels help with twins.
fn in_plane_axes(
    vertices: &[Vector3<f64>],
    axis: &Unit<Vector3<f64>>,
    radius: f64,
    level: f64,
) -> Vec<Unit<Vector3<f64>>> {
    let (b1, b2) = plane_basis(axis);
    let mut polar: Vec<(f64, f64)> = vertices
        .iter()
        .filter_map(|v| {
            let w = v - axis.into_inner() * v.dot(axis);
            let r = w.norm();
            (r >= MIN_OFF_AXIS * radius).then(|| (r, w.dot(&b2).atan2(w.dot(&b1)).rem_euclid(PI)))
        })
        .collect();
    polar.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut lines = Vec::new();
    let mut budget = MAX_PLANE_ANGLES;
    let mut start = 0;
    while start < polar.len() {
        let top = polar[start].0;
        let end = start + polar[start..].partition_point(|p| p.0 >= top - level);
        let mut angles: Vec<f64> = polar[start..end].iter().map(|p| p.1).collect();
        angles.sort_by(f64::total_cmp);
        angles.dedup_by(|a, b| (*a - *b).abs() < SAME_LINE);
        if angles.len() > budget {
            if lines.is_empty() {
                let stride = angles.len().div_ceil(budget);
                lines.extend(angles.iter().step_by(stride));
            }
            break;
        }
        budget -= angles.len();
        lines.extend(with_bisectors(&angles));
        start = end;
    }
    lines
        .into_iter()
        .map(|a| Unit::new_normalize(b1 * a.cos() + b2 * a.sin()))
        .collect()
}

/// Sorted line angles in [0, π) followed by the bisector of each pair of
/// neighbours (cyclically, the last with the first plus π).
fn with_bisectors(angles: &[f64]) -> Vec<f64> {
    let n = angles.len();
    let bisectors = (0..n).map(|i| {
        let next = if i + 1 < n {
            angles[i + 1]
        } else {
            angles[0] + PI
        };
        0.5 * (angles[i] + next)
    });
    angles.iter().copied().chain(bisectors).collect()
}

/// Directions of the vertices within `level` of the bounding radius: any
/// symmetry permutes them (the farthest surface points are vertices).
fn farthest_directions(
    vertices: &[Vector3<f64>],
    radius: f64,
    level: f64,
) -> Vec<Unit<Vector3<f64>>> {
    let mut far: Vec<&Vector3<f64>> = vertices
        .iter()
        .filter(|v| v.norm() >= radius - level)
        .collect();
    far.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    let mut out: Vec<Unit<Vector3<f64>>> = Vec::new();
    for v in far {
        let d = Unit::new_normalize(*v);
        if !out
            .iter()
            .any(|o| (o.into_inner() - d.into_inner()).norm() < SAME_LINE)
        {
            out.push(d);
            if out.len() == MAX_FARTHEST {
                break;
            }
        }
    }
    out
}

/// Half-turn axes from pairs of farthest directions: a half-turn maps `v` to
/// `w` only about the line of `v + w`.
fn pair_sums(dirs: &[Unit<Vector3<f64>>]) -> Vec<Unit<Vector3<f64>>> {
    let mut out = Vec::new();
    for (i, a) in dirs.iter().enumerate() {
        for b in &dirs[i + 1..] {
            let s = a.into_inner() + b.into_inner();
            if s.norm() > MIN_OFF_AXIS {
                out.push(Unit::new_normalize(s));
            }
        }
    }
    out
}

#[cfg(test)]
#[path = "axes_tests.rs"]
mod tests;
