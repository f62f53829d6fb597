//! Scoring a rotation by the distance from the rotated surface to the mesh
//! (see the method in [`crate::symmetry`]).

use nalgebra::{Rotation3, Vector3};
use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;

use super::options::{SymmetryOptions, TWIN_QUANTILE};
use crate::error::TargetError;
use crate::mesh::Mesh;
use crate::sampling::sample_mesh_surface;

/// Area samples scored by the first, cheap look at every candidate.
const SCREEN_POINTS: usize = 256;
/// Area samples scored before a twin may be accepted early.
const EARLY_ACCEPT_POINTS: usize = 400;
/// Width (standard deviations) of the sequential test on the share of
/// samples beyond the twin bound.
const SIGMAS: f64 = 4.0;

/// Distances (m) of the moved samples to the surface, over the samples scored.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Errors {
    /// Largest (area samples and, if scored, vertices).
    pub(crate) max: f64,
    /// Mean over the area samples.
    pub(crate) mean: f64,
    /// Median over the area samples.
    pub(crate) median: f64,
    /// [`TWIN_QUANTILE`] quantile over the area samples.
    pub(crate) quantile: f64,
    /// Points scored.
    pub(crate) points: usize,
}

/// What the first look at a rotation says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Screen {
    /// Every sample looked at is within the tolerance.
    Symmetric,
    /// Too few samples are beyond the twin bound to rule a twin out.
    Twin,
    /// Clearly too many samples beyond the twin bound.
    Rejected,
}

/// Running count of the distances of one rotation.
struct Tally {
    distances: Vec<f64>,
    beyond: usize,
    max: f64,
    bound: f64,
}

impl Tally {
    fn new(bound: f64) -> Tally {
        Tally {
            distances: Vec::new(),
            beyond: 0,
            max: 0.0,
            bound,
        }
    }

    fn push(&mut self, d: f64) {
        self.distances.push(d);
        self.max = self.max.max(d);
        self.beyond += usize::from(d > self.bound);
    }

    /// Expected count beyond the bound for a twin at the limit, and the
    /// sequential test's margin around it.
    fn limit_and_margin(&self) -> (f64, f64) {
        let n = self.distances.len() as f64;
        let p = 1.0 - TWIN_QUANTILE;
        (p * n, SIGMAS * (n * p * (1.0 - p)).sqrt() + 1.0)
    }

    fn clearly_too_many(&self) -> bool {
        let (limit, margin) = self.limit_and_margin();
        self.beyond as f64 > limit + margin
    }

    fn clearly_few(&self) -> bool {
        let (limit, margin) = self.limit_and_margin();
        self.distances.len() >= EARLY_ACCEPT_POINTS && (self.beyond as f64) + margin < limit
    }

    fn within_quantile(&self) -> bool {
        let (limit, _) = self.limit_and_margin();
        self.beyond as f64 <= limit
    }

    fn errors(mut self, extra_points: usize, extra_max: f64) -> Errors {
        let n = self.distances.len();
        let mut pick = |q: f64| {
            if n == 0 {
                return 0.0;
            }
            let k = ((q * n as f64).ceil() as usize).clamp(1, n) - 1;
            *self.distances.select_nth_unstable_by(k, f64::total_cmp).1
        };
        let median = pick(0.5);
        let quantile = pick(TWIN_QUANTILE);
        let mean = self.distances.iter().sum::<f64>() / n.max(1) as f64;
        Errors {
            max: self.max.max(extra_max),
            mean,
            median,
            quantile,
            points: n + extra_points,
        }
    }
}

/// The samples of one mesh and the bounds they are held to.
pub(crate) struct Scorer<'a> {
    mesh: &'a Mesh,
    area: Vec<Vector3<f64>>,
    vertices: Vec<Vector3<f64>>,
    /// Distance (m) within which a symmetry maps every sample.
    pub(crate) tolerance: f64,
    twin_bound: f64,
}

impl<'a> Scorer<'a> {
    /// Samples `mesh` (bounding radius `radius`): area-uniform points at the
    /// options' spacing, widened so that there are at most
    /// `options.max_samples`, and the vertices of faces of non-zero area (at
    /// most as many), each in a seeded random order.
    pub(crate) fn new(
        mesh: &'a Mesh,
        options: &SymmetryOptions,
        radius: f64,
    ) -> Result<Scorer<'a>, TargetError> {
        let cap = options.max_samples;
        let spacing = (options.sample_spacing_fraction * radius)
            .max((mesh.surface_area() / cap as f64).sqrt());
        let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
        let mut area = sample_mesh_surface(mesh, spacing, options.seed)?;
        area.shuffle(&mut rng);
        area.truncate(cap);
        let mut used = vec![false; mesh.vertices().len()];
        for (t, &a) in mesh.triangles().iter().zip(mesh.face_areas()) {
            if a > 0.0 {
                t.iter().for_each(|&k| used[k as usize] = true);
            }
        }
        let mut vertices: Vec<Vector3<f64>> = mesh
            .vertices()
            .iter()
            .zip(&used)
            .filter_map(|(v, &u)| u.then_some(*v))
            .collect();
        vertices.shuffle(&mut rng);
        vertices.truncate(cap);
        if area.is_empty() {
            return Err(TargetError::InvalidMesh(format!(
                "no surface sample at spacing {spacing} m for symmetry detection"
            )));
        }
        Ok(Scorer {
            mesh,
            area,
            vertices,
            tolerance: options.tolerance_fraction * radius,
            twin_bound: options.twin_fraction * radius,
        })
    }

    /// Number of area samples and of vertices.
    pub(crate) fn sizes(&self) -> (usize, usize) {
        (self.area.len(), self.vertices.len())
    }

    fn error(&self, s: &Rotation3<f64>, p: &Vector3<f64>) -> f64 {
        self.mesh.distance_to_surface(&(s * p))
    }

    /// First look: up to [`SCREEN_POINTS`] area samples, stopping as soon as
    /// the share beyond the twin bound is clearly above 1 − [`TWIN_QUANTILE`].
    pub(crate) fn screen(&self, s: &Rotation3<f64>) -> (Screen, Errors) {
        let mut tally = Tally::new(self.twin_bound);
        for p in self.area.iter().take(SCREEN_POINTS) {
            tally.push(self.error(s, p));
            if tally.clearly_too_many() {
                return (Screen::Rejected, tally.errors(0, 0.0));
            }
        }
        let verdict = if tally.max <= self.tolerance {
            Screen::Symmetric
        } else {
            Screen::Twin
        };
        (verdict, tally.errors(0, 0.0))
    }

    /// Mean distance over the first [`SCREEN_POINTS`] area samples: the
    /// same samples for every rotation, so that means compare.
    pub(crate) fn mean_error(&self, s: &Rotation3<f64>) -> f64 {
        let points = &self.area[..self.area.len().min(SCREEN_POINTS)];
        points.iter().map(|p| self.error(s, p)).sum::<f64>() / points.len().max(1) as f64
    }

    /// Full check of a symmetry: every area sample, then every vertex, within
    /// the tolerance. Stops at the first one beyond it (`false`, with the
    /// errors of the points scored so far).
    pub(crate) fn confirm_symmetry(&self, s: &Rotation3<f64>) -> (bool, Errors) {
        let mut tally = Tally::new(self.twin_bound);
        for p in &self.area {
            tally.push(self.error(s, p));
            if tally.max > self.tolerance {
                return (false, tally.errors(0, 0.0));
            }
        }
        let mut vertex_max: f64 = 0.0;
        for (k, p) in self.vertices.iter().enumerate() {
            vertex_max = vertex_max.max(self.error(s, p));
            if vertex_max > self.tolerance {
                return (false, tally.errors(k + 1, vertex_max));
            }
        }
        (true, tally.errors(self.vertices.len(), vertex_max))
    }

    /// Full check of a twin on the area samples: whether the
    /// [`TWIN_QUANTILE`] quantile is within the twin bound. Stops early once
    /// the share beyond the bound is clearly above or (after
    /// [`EARLY_ACCEPT_POINTS`]) clearly below its limit.
    pub(crate) fn confirm_twin(&self, s: &Rotation3<f64>) -> (bool, Errors) {
        let mut tally = Tally::new(self.twin_bound);
        for p in &self.area {
            tally.push(self.error(s, p));
            if tally.clearly_too_many() {
                return (false, tally.errors(0, 0.0));
            }
            if tally.clearly_few() {
                return (true, tally.errors(0, 0.0));
            }
        }
        (tally.within_quantile(), tally.errors(0, 0.0))
    }
}
