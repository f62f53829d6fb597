//! The target as built, against the target as modelled (issue 25 item 3:
//! no "inverse crime", where the simulator renders the very mesh the
//! estimators match). A nominal target is perturbed the way a real
//! spacecraft departs from its CAD model:
//!
//! - **surface relief on MLI faces**: blankets bulge between their
//!   attachments; every MLI triangle is subdivided to `relief_cell_m` and
//!   its inner vertices pushed along the face normal by a smooth random
//!   field of standard deviation `relief_m` (zero on the triangle's edges,
//!   so no crack opens at a crease);
//! - **small appendages missing from the model**: `appendages` boxes
//!   (sensors, thrusters, harness) of `appendage_size` × the bounding
//!   radius, on area-weighted random points of the surface, along its
//!   normal;
//! - **dimensional errors**: each body axis scaled by `1 + ε`, `ε` drawn
//!   with standard deviation `scale_sigma`;
//! - **a displaced centre of mass**: the true centre of mass is
//!   `com_offset` × the bounding radius from the modelled origin, in a
//!   random direction. The as-built body frame has its origin at the true
//!   centre of mass and the model's axes, so its truth pose is compared
//!   with the estimate as it is.
//!
//! Every draw comes from one seed: the same seed builds the same target.

use crate::error::TargetError;
use crate::material::{MaterialClass, MaterialId};
use crate::mesh::Mesh;
use crate::target::Target;
use nalgebra::{Rotation3, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// How the as-built target departs from its model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AsBuilt {
    /// Standard deviation of the MLI relief (m).
    pub relief_m: f64,
    /// Edge of the subdivided MLI triangles (m), about half the relief's
    /// wavelength.
    pub relief_cell_m: f64,
    /// Boxes on the target that the model does not have.
    pub appendages: usize,
    /// Their size range, as fractions of the bounding radius.
    pub appendage_size: [f64; 2],
    /// Standard deviation of the scale error of each body axis.
    pub scale_sigma: f64,
    /// Distance of the true centre of mass from the modelled origin, as a
    /// fraction of the bounding radius.
    pub com_offset: f64,
}

impl Default for AsBuilt {
    /// 2 cm of relief in 15 cm cells; three appendages of 4-10 % of the
    /// radius; 1 % dimensional errors; the centre of mass 2 % of the radius
    /// off (3 cm on deos).
    fn default() -> Self {
        AsBuilt {
            relief_m: 0.02,
            relief_cell_m: 0.15,
            appendages: 3,
            appendage_size: [0.04, 0.10],
            scale_sigma: 0.01,
            com_offset: 0.02,
        }
    }
}

impl AsBuilt {
    /// Fails on a negative, non-finite or inconsistent value.
    pub fn validate(&self) -> Result<(), TargetError> {
        let bad = |what: &str| Err(TargetError::InvalidMesh(format!("as-built: {what}")));
        let non_negative = |v: f64| v.is_finite() && v >= 0.0;
        if !(non_negative(self.relief_m)
            && self.relief_cell_m.is_finite()
            && self.relief_cell_m > 0.0)
        {
            return bad("relief_m >= 0 and relief_cell_m > 0, finite");
        }
        let [lo, hi] = self.appendage_size;
        if !(non_negative(lo) && hi.is_finite() && lo <= hi && hi < 1.0) {
            return bad("appendage_size = [lo, hi] with 0 <= lo <= hi < 1");
        }
        if !(non_negative(self.scale_sigma) && self.scale_sigma < 0.2) {
            return bad("scale_sigma in [0, 0.2)");
        }
        if !(non_negative(self.com_offset) && self.com_offset < 0.5) {
            return bad("com_offset in [0, 0.5)");
        }
        Ok(())
    }

    /// The as-built version of `nominal`, drawn from `seed`. Its name is
    /// the nominal one with "as built" appended; it declares no symmetry
    /// (the perturbations break them).
    pub fn apply(&self, nominal: &Target, seed: u64) -> Result<Target, TargetError> {
        self.validate()?;
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x00a5_b117_00d5);
        let r = nominal.bounding_radius();
        let mli: Vec<bool> = nominal
            .materials()
            .iter()
            .map(|m| m.class == MaterialClass::Mli)
            .collect();
        let relief = Relief::draw(self.relief_m, 2.0 * self.relief_cell_m, &mut rng);
        let mesh = with_relief(nominal.mesh(), &mli, self.relief_cell_m, &relief)?;
        let mesh = self.with_appendages(mesh, r, &mut rng)?;
        let scale = Vector3::from_fn(|_, _| 1.0 + self.scale_sigma * gaussian(&mut rng));
        let com = unit(&mut rng) * (self.com_offset * r);
        let vertices = mesh
            .vertices()
            .iter()
            .map(|v| v.component_mul(&scale) - com)
            .collect();
        let mesh = Mesh::new(
            vertices,
            mesh.triangles().to_vec(),
            mesh.face_materials().to_vec(),
        )?;
        Target::new(
            &format!("{} as built", nominal.name()),
            mesh,
            nominal.materials().to_vec(),
            vec![Rotation3::identity()],
        )
    }

    /// `mesh` with the appendage boxes, each on a surface point drawn by
    /// area, standing on it along its normal, in the material of the
    /// structure if the target has one (else the first).
    fn with_appendages(
        &self,
        mesh: Mesh,
        radius: f64,
        rng: &mut ChaCha8Rng,
    ) -> Result<Mesh, TargetError> {
        if self.appendages == 0 {
            return Ok(mesh);
        }
        let total: f64 = mesh.face_areas().iter().sum();
        let mut parts = vec![mesh.clone()];
        for _ in 0..self.appendages {
            let mut pick = rng.random_range(0.0..total);
            let face = mesh
                .face_areas()
                .iter()
                .position(|a| {
                    pick -= a;
                    pick <= 0.0
                })
                .unwrap_or(0);
            let [a, b, c] = mesh.triangles()[face].map(|k| mesh.vertices()[k as usize]);
            let (u, v): (f64, f64) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
            let (u, v) = if u + v > 1.0 {
                (1.0 - u, 1.0 - v)
            } else {
                (u, v)
            };
            let at = a + (b - a) * u + (c - a) * v;
            let normal = mesh.face_normals()[face];
            let [lo, hi] = self.appendage_size;
            let size = radius * rng.random_range(lo..=hi.max(lo + 1e-9));
            let half = Vector3::new(0.5 * size, 0.3 * size, 0.3 * size);
            // The box's long axis along the normal, its base on the face.
            let rotation = Rotation3::rotation_between(&Vector3::x(), &normal)
                .unwrap_or_else(Rotation3::identity);
            let material = mesh.face_materials()[face];
            parts.push(Mesh::try_cuboid(
                at + normal * half.x,
                half,
                rotation,
                material,
            )?);
        }
        Mesh::merged(&parts)
    }
}

/// A smooth random height field: a sum of plane waves of one wavelength in
/// random directions, scaled to a standard deviation.
struct Relief {
    waves: Vec<(Vector3<f64>, f64)>,
    amplitude: f64,
}

impl Relief {
    const WAVES: usize = 8;

    fn draw(sigma_m: f64, wavelength_m: f64, rng: &mut ChaCha8Rng) -> Relief {
        let k = 2.0 * std::f64::consts::PI / wavelength_m;
        let waves = (0..Self::WAVES)
            .map(|_| (unit(rng) * k, rng.random_range(0.0..std::f64::consts::TAU)))
            .collect();
        // Each wave has variance 1/2: the sum has WAVES / 2.
        let amplitude = sigma_m / (Self::WAVES as f64 / 2.0).sqrt();
        Relief { waves, amplitude }
    }

    fn height(&self, p: &Vector3<f64>) -> f64 {
        self.amplitude
            * self
                .waves
                .iter()
                .map(|(k, phase)| (k.dot(p) + phase).sin())
                .sum::<f64>()
    }
}

/// `mesh` with its MLI triangles (`mli[material]`) subdivided to edges of
/// at most `cell_m` and their inner vertices raised by `relief` along the
/// face normal, weighted by `27 u v w` (1 at the centroid, 0 on the edges).
fn with_relief(
    mesh: &Mesh,
    mli: &[bool],
    cell_m: f64,
    relief: &Relief,
) -> Result<Mesh, TargetError> {
    let mut vertices = mesh.vertices().to_vec();
    let mut triangles = Vec::with_capacity(mesh.triangle_count());
    let mut materials = Vec::with_capacity(mesh.triangle_count());
    for (t, (&tri, &m)) in mesh
        .triangles()
        .iter()
        .zip(mesh.face_materials())
        .enumerate()
    {
        if !mli.get(usize::from(m)).copied().unwrap_or(false) || relief.amplitude == 0.0 {
            triangles.push(tri);
            materials.push(m);
            continue;
        }
        let corners = tri.map(|k| mesh.vertices()[k as usize]);
        let normal = mesh.face_normals()[t];
        subdivide(
            &corners,
            normal,
            cell_m,
            relief,
            m,
            &mut vertices,
            &mut triangles,
            &mut materials,
        )?;
    }
    Mesh::new(vertices, triangles, materials)
}

/// One triangle split into `n²` (n = longest edge / cell, rounded up, at
/// most 64) with the relief applied; appended to the buffers.
#[allow(clippy::too_many_arguments)]
fn subdivide(
    [a, b, c]: &[Vector3<f64>; 3],
    normal: Vector3<f64>,
    cell_m: f64,
    relief: &Relief,
    material: MaterialId,
    vertices: &mut Vec<Vector3<f64>>,
    triangles: &mut Vec<[u32; 3]>,
    materials: &mut Vec<MaterialId>,
) -> Result<(), TargetError> {
    let longest = (b - a).norm().max((c - b).norm()).max((a - c).norm());
    let n = ((longest / cell_m).ceil() as usize).clamp(1, 64);
    let base = u32::try_from(vertices.len())
        .map_err(|_| TargetError::InvalidMesh("too many vertices".into()))?;
    // Vertex (i, j), i + j <= n, at a + (b - a) i/n + (c - a) j/n.
    let index = |i: usize, j: usize| base + (i * (2 * n + 3 - i) / 2 + j) as u32;
    for i in 0..=n {
        for j in 0..=(n - i) {
            let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
            let p = a + (b - a) * u + (c - a) * v;
            let window = 27.0 * u * v * (1.0 - u - v);
            vertices.push(p + normal * (window * relief.height(&p)));
        }
    }
    for i in 0..n {
        for j in 0..(n - i) {
            triangles.push([index(i, j), index(i + 1, j), index(i, j + 1)]);
            materials.push(material);
            if i + j + 1 < n {
                triangles.push([index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)]);
                materials.push(material);
            }
        }
    }
    Ok(())
}

/// A unit vector uniform on the sphere.
fn unit(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let n = v.norm();
        if n > 1e-3 && n <= 1.0 {
            return v / n;
        }
    }
}

/// A standard normal draw (Box-Muller).
fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    let u: f64 = rng.random_range(f64::EPSILON..1.0);
    let v: f64 = rng.random_range(0.0..1.0);
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

#[cfg(test)]
#[path = "as_built_tests.rs"]
mod tests;
