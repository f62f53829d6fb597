//! Triangle mesh with a material per face and BVH ray casting.
//!
//! Geometry is stored in `f64` (nalgebra) and mirrored in a parry3d `TriMesh` (`f32`, glam
//! types) that owns the bounding volume hierarchy. A ray cast runs in three steps:
//! 1. reject the ray against the mesh's bounding sphere in `f64` (cheap, most rays of a
//!    lidar scan miss a small target), and clip it to the sphere;
//! 2. find the first triangle with parry's BVH in `f32`, the ray origin moved to the sphere
//!    entry so that `f32` coordinates stay of the size of the mesh;
//! 3. recompute distance and normal exactly in `f64` from the plane of that triangle.

use nalgebra::{Rotation3, Vector3};
use parry3d::math::Vector as Vec3f;
use parry3d::shape::TriMesh;

use crate::error::TargetError;
use crate::material::MaterialId;

mod ray_cast;

/// First intersection of a ray with a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// Distance from the ray origin to the hit point along the unit direction (m).
    pub distance: f64,
    /// Unit normal of the hit face, oriented back toward the ray origin.
    pub normal: Vector3<f64>,
    /// Index of the hit triangle.
    pub face: u32,
    /// Material of the hit triangle.
    pub material: MaterialId,
}

/// Triangle mesh with a [`MaterialId`] per face and a BVH for ray casting.
#[derive(Clone)]
pub struct Mesh {
    vertices: Vec<Vector3<f64>>,
    triangles: Vec<[u32; 3]>,
    face_materials: Vec<MaterialId>,
    /// Unit normals from the winding (right-hand rule); zero for degenerate triangles.
    face_normals: Vec<Vector3<f64>>,
    face_areas: Vec<f64>,
    surface_area: f64,
    sphere_center: Vector3<f64>,
    sphere_radius: f64,
    bvh: TriMesh,
}

impl std::fmt::Debug for Mesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Mesh")
            .field("vertices", &self.vertices.len())
            .field("triangles", &self.triangles.len())
            .field("surface_area", &self.surface_area)
            .field("sphere_center", &self.sphere_center)
            .field("sphere_radius", &self.sphere_radius)
            .finish()
    }
}

fn to_f32(v: &Vector3<f64>) -> Vec3f {
    Vec3f::new(v.x as f32, v.y as f32, v.z as f32)
}

fn invalid(message: String) -> TargetError {
    TargetError::InvalidMesh(message)
}

impl Mesh {
    /// Builds a mesh from vertices, triangles (indices into `vertices`) and one material per
    /// triangle.
    ///
    /// Errors: no vertex or no triangle, a non-finite vertex (or one beyond `f32` range),
    /// an index out of range, `face_materials.len() != triangles.len()`, or a zero total
    /// area. Individual zero-area triangles are kept: no ray hits them and no sample lands
    /// on them, so they are harmless (CAD exports often contain a few).
    pub fn new(
        vertices: Vec<Vector3<f64>>,
        triangles: Vec<[u32; 3]>,
        face_materials: Vec<MaterialId>,
    ) -> Result<Mesh, TargetError> {
        if vertices.is_empty() || triangles.is_empty() {
            return Err(invalid(format!(
                "empty mesh ({} vertices, {} triangles)",
                vertices.len(),
                triangles.len()
            )));
        }
        if face_materials.len() != triangles.len() {
            return Err(invalid(format!(
                "{} face materials for {} triangles",
                face_materials.len(),
                triangles.len()
            )));
        }
        if let Some(i) = vertices.iter().position(|v| {
            v.iter()
                .any(|c| !(c.is_finite() && (*c as f32).is_finite()))
        }) {
            return Err(invalid(format!(
                "vertex {i} is not finite: {:?}",
                vertices[i]
            )));
        }
        let n = vertices.len();
        if let Some(t) = triangles
            .iter()
            .position(|t| t.iter().any(|&k| k as usize >= n))
        {
            return Err(invalid(format!(
                "triangle {t} {:?} indexes past the {n} vertices",
                triangles[t]
            )));
        }
        let (face_normals, face_areas): (Vec<_>, Vec<_>) = triangles
            .iter()
            .map(|t| normal_and_area(&vertices, t))
            .unzip();
        let surface_area: f64 = face_areas.iter().sum();
        if !(surface_area > 0.0 && surface_area.is_finite()) {
            return Err(invalid(format!(
                "degenerate mesh: total area {surface_area}"
            )));
        }
        let (sphere_center, sphere_radius) = bounding_sphere_of(&vertices);
        let bvh = TriMesh::new(vertices.iter().map(to_f32).collect(), triangles.clone())
            .map_err(|e| invalid(format!("BVH construction failed: {e:?}")))?;
        Ok(Mesh {
            vertices,
            triangles,
            face_materials,
            face_normals,
            face_areas,
            surface_area,
            sphere_center,
            sphere_radius,
            bvh,
        })
    }

    /// Box of the given half extents (m), rotated by `rotation` about its centre then moved to
    /// `center`; 12 triangles wound so that their normals point outward.
    ///
    /// # Panics
    /// If an input is not finite or all half extents are zero. Use [`Mesh::try_cuboid`] for
    /// inputs that are not program constants.
    pub fn cuboid(
        center: Vector3<f64>,
        half_extents: Vector3<f64>,
        rotation: Rotation3<f64>,
        material: MaterialId,
    ) -> Mesh {
        match Mesh::try_cuboid(center, half_extents, rotation, material) {
            Ok(mesh) => mesh,
            Err(e) => panic!("Mesh::cuboid: {e}"),
        }
    }

    /// Fallible [`Mesh::cuboid`]: non-finite inputs or a zero-size box are errors.
    pub fn try_cuboid(
        center: Vector3<f64>,
        half_extents: Vector3<f64>,
        rotation: Rotation3<f64>,
        material: MaterialId,
    ) -> Result<Mesh, TargetError> {
        let h = half_extents.abs();
        let vertices: Vec<Vector3<f64>> = (0..8u32)
            .map(|i| {
                let sign = |bit: u32| if i & bit == 0 { -1.0 } else { 1.0 };
                center + rotation * Vector3::new(sign(1) * h.x, sign(2) * h.y, sign(4) * h.z)
            })
            .collect();
        // Each face: the 4 corners whose bit `axis` equals `high`, as a quad in cyclic order.
        let mut quads = Vec::with_capacity(6);
        for (bit, others) in [(1u32, [2u32, 4]), (2, [1, 4]), (4, [1, 2])] {
            for high in [0, bit] {
                let [a, b] = others;
                quads.push([high, high | a, high | a | b, high | b]);
            }
        }
        let triangles: Vec<[u32; 3]> = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        let triangles = orient_outward(&vertices, triangles, &center);
        let materials = vec![material; triangles.len()];
        Mesh::new(vertices, triangles, materials)
    }

    /// Concatenation of several meshes (faces keep their materials and their order: the
    /// faces of `meshes[0]` come first). Overlapping parts are allowed.
    pub fn merged(meshes: &[Mesh]) -> Result<Mesh, TargetError> {
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        let mut materials = Vec::new();
        for m in meshes {
            let offset = u32::try_from(vertices.len())
                .map_err(|_| invalid("more than u32::MAX vertices".to_owned()))?;
            vertices.extend_from_slice(&m.vertices);
            triangles.extend(m.triangles.iter().map(|t| t.map(|k| k + offset)));
            materials.extend_from_slice(&m.face_materials);
        }
        Mesh::new(vertices, triangles, materials)
    }

    /// This mesh with every vertex mapped by `v -> rotation * v + translation`.
    pub fn transformed(
        &self,
        rotation: &Rotation3<f64>,
        translation: &Vector3<f64>,
    ) -> Result<Mesh, TargetError> {
        let vertices = self
            .vertices
            .iter()
            .map(|v| rotation * v + translation)
            .collect();
        Mesh::new(
            vertices,
            self.triangles.clone(),
            self.face_materials.clone(),
        )
    }

    /// This mesh with every coordinate multiplied by `scale` (must be finite and > 0).
    pub fn scaled(&self, scale: f64) -> Result<Mesh, TargetError> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(invalid(format!("scale {scale} must be finite and > 0")));
        }
        let vertices = self.vertices.iter().map(|v| v * scale).collect();
        Mesh::new(
            vertices,
            self.triangles.clone(),
            self.face_materials.clone(),
        )
    }

    /// Bounding sphere: centre of the axis-aligned bounding box and the largest distance of a
    /// vertex from it (m).
    pub fn bounding_sphere(&self) -> (Vector3<f64>, f64) {
        (self.sphere_center, self.sphere_radius)
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Total area of the triangles (m²).
    pub fn surface_area(&self) -> f64 {
        self.surface_area
    }

    /// Area-weighted centroid of the triangles: the centre of mass of a uniform thin shell.
    pub fn area_weighted_centroid(&self) -> Vector3<f64> {
        let sum = self.triangles.iter().zip(&self.face_areas).fold(
            Vector3::zeros(),
            |acc, (t, &area)| {
                let c = t
                    .iter()
                    .fold(Vector3::zeros(), |s, &k| s + self.vertices[k as usize]);
                acc + c * (area / 3.0)
            },
        );
        sum / self.surface_area
    }

    /// Vertices (m).
    pub fn vertices(&self) -> &[Vector3<f64>] {
        &self.vertices
    }

    /// Triangles as indices into [`Mesh::vertices`].
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Material of each triangle.
    pub fn face_materials(&self) -> &[MaterialId] {
        &self.face_materials
    }

    /// Unit normal of each triangle from its winding (zero for a degenerate triangle).
    pub fn face_normals(&self) -> &[Vector3<f64>] {
        &self.face_normals
    }

    /// Area of each triangle (m²).
    pub fn face_areas(&self) -> &[f64] {
        &self.face_areas
    }
}

/// Unit normal (right-hand winding, zero if degenerate) and area of a triangle.
fn normal_and_area(vertices: &[Vector3<f64>], t: &[u32; 3]) -> (Vector3<f64>, f64) {
    let [a, b, c] = t.map(|k| vertices[k as usize]);
    let cross = (b - a).cross(&(c - a));
    let norm = cross.norm();
    if norm > 0.0 {
        (cross / norm, 0.5 * norm)
    } else {
        (Vector3::zeros(), 0.0)
    }
}

/// Centre of the axis-aligned bounding box and largest vertex distance from it.
fn bounding_sphere_of(vertices: &[Vector3<f64>]) -> (Vector3<f64>, f64) {
    let (lo, hi) = vertices.iter().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), v| (lo.inf(v), hi.sup(v)),
    );
    let center = (lo + hi) * 0.5;
    let radius = vertices
        .iter()
        .map(|v| (v - center).norm())
        .fold(0.0, f64::max);
    (center, radius)
}

/// Flips triangles of a convex solid so that their normals point away from `interior`.
pub(crate) fn orient_outward(
    vertices: &[Vector3<f64>],
    triangles: Vec<[u32; 3]>,
    interior: &Vector3<f64>,
) -> Vec<[u32; 3]> {
    triangles
        .into_iter()
        .map(|t| {
            let (n, _) = normal_and_area(vertices, &t);
            let centroid = t
                .iter()
                .fold(Vector3::zeros(), |s, &k| s + vertices[k as usize])
                / 3.0;
            if n.dot(&(centroid - interior)) < 0.0 {
                [t[0], t[2], t[1]]
            } else {
                t
            }
        })
        .collect()
}

#[cfg(test)]
#[path = "mesh_tests.rs"]
mod tests;
