//! A target spacecraft: mesh in the body frame, materials, symmetry group.

use std::path::Path;

use nalgebra::{Rotation3, Vector3};

use crate::error::TargetError;
use crate::material::Material;
use crate::mesh::{Mesh, RayHit};
use crate::{loaders, sampling};

/// A target model. The mesh is expressed in the target body frame, whose origin is the
/// centre of mass (each built-in target documents its axes; loaded meshes use the
/// area-weighted centroid, see [`Target::load`]).
///
/// `Target` is immutable, `Send + Sync`, and meant to be shared behind an `Arc`.
#[derive(Clone, Debug)]
pub struct Target {
    name: String,
    mesh: Mesh,
    materials: Vec<Material>,
    symmetries: Vec<Rotation3<f64>>,
    twins: Vec<Rotation3<f64>>,
    bounding_radius: f64,
}

impl Target {
    /// Names accepted by [`Target::builtin`].
    pub const BUILTIN: &'static [&'static str] = &["envisat", "deos"];

    /// Assembles a target. Errors if a face uses a material id without a material, a material
    /// is invalid, or `symmetries` does not start with the identity (within 1e-9) or holds a
    /// non-finite rotation.
    pub fn new(
        name: &str,
        mesh: Mesh,
        materials: Vec<Material>,
        symmetries: Vec<Rotation3<f64>>,
    ) -> Result<Target, TargetError> {
        let bad = |message: String| TargetError::InvalidTarget {
            name: name.to_owned(),
            message,
        };
        if let Some(&id) = mesh
            .face_materials()
            .iter()
            .find(|&&id| usize::from(id) >= materials.len())
        {
            return Err(bad(format!(
                "material id {id} used but only {} materials",
                materials.len()
            )));
        }
        for m in &materials {
            m.validate().map_err(&bad)?;
        }
        match symmetries.first() {
            Some(first) if first.angle() < 1e-9 => {}
            _ => return Err(bad("symmetries must start with the identity".to_owned())),
        }
        if symmetries
            .iter()
            .any(|s| s.matrix().iter().any(|c| !c.is_finite()))
        {
            return Err(bad("non-finite symmetry rotation".to_owned()));
        }
        let bounding_radius = mesh
            .vertices()
            .iter()
            .map(Vector3::norm)
            .fold(0.0, f64::max);
        Ok(Target {
            name: name.to_owned(),
            mesh,
            materials,
            symmetries,
            twins: Vec::new(),
            bounding_radius,
        })
    }

    /// This target with its near-symmetric twins declared (see
    /// [`Target::twins`]). Errors on a non-finite rotation.
    pub fn with_twins(mut self, twins: Vec<Rotation3<f64>>) -> Result<Target, TargetError> {
        if twins
            .iter()
            .any(|s| s.matrix().iter().any(|c| !c.is_finite()))
        {
            return Err(TargetError::InvalidTarget {
                name: self.name,
                message: "non-finite twin rotation".to_owned(),
            });
        }
        self.twins = twins;
        Ok(self)
    }

    /// Loads an STL, OBJ or PLY mesh (chosen by the case-insensitive extension).
    ///
    /// Coordinates are read in the file's own units and multiplied by `scale`; the result is
    /// in metres (so a file in millimetres needs `scale = 0.001`). The body frame keeps the
    /// file's axes, with its origin moved to the area-weighted centroid of the surface: the
    /// centre of mass under a uniform-shell assumption. This is the frame convention of every
    /// loaded target. The whole mesh gets one material ([`Material::default_structure`]:
    /// structure, ρ = 0.6) and the symmetry group is the identity alone.
    pub fn load(path: &Path, scale: f64) -> Result<Target, TargetError> {
        let (name, mesh) = loaders::load_mesh(path, scale)?;
        Target::new(
            &name,
            mesh,
            vec![Material::default_structure()],
            vec![Rotation3::identity()],
        )
    }

    /// This target renamed, with another symmetry group and twins (checked
    /// as in [`Target::new`]): what a package records.
    pub fn with_symmetries(
        self,
        name: &str,
        symmetries: Vec<Rotation3<f64>>,
        twins: Vec<Rotation3<f64>>,
    ) -> Result<Target, TargetError> {
        Target::new(name, self.mesh, self.materials, symmetries)?.with_twins(twins)
    }

    /// [`Target::load`], also returning where the body origin (the
    /// area-weighted centroid) lies in the file's frame, scaled (m).
    pub fn load_with_origin(
        path: &Path,
        scale: f64,
    ) -> Result<(Target, Vector3<f64>), TargetError> {
        let (name, mesh, origin) = loaders::load_mesh_with_origin(path, scale)?;
        let target = Target::new(
            &name,
            mesh,
            vec![Material::default_structure()],
            vec![Rotation3::identity()],
        )?;
        Ok((target, origin))
    }

    /// This target with all coordinates multiplied by `scale` (origin, materials and
    /// symmetries unchanged). `spec` only names the target in the error message.
    pub(crate) fn scaled(self, spec: &str, scale: f64) -> Result<Target, TargetError> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(TargetError::InvalidScale {
                spec: spec.to_owned(),
                scale,
            });
        }
        if scale == 1.0 {
            return Ok(self);
        }
        let mesh = self.mesh.scaled(scale)?;
        Target::new(&self.name, mesh, self.materials, self.symmetries)?.with_twins(self.twins)
    }

    /// Name of the target ("envisat", "deos", or the file stem of a loaded mesh).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Mesh in the target body frame (origin at the centre of mass).
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// Materials, indexed by [`crate::MaterialId`].
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// Rotations `S_k` of the body frame that leave the shape unchanged (seed 004 Eq. (14):
    /// attitude `Q` is equivalent to `Q S_k`). Always starts with the identity.
    pub fn symmetries(&self) -> &[Rotation3<f64>] {
        &self.symmetries
    }

    /// Near-symmetric twins: rotations `F`, not symmetries, that map most
    /// of the surface onto itself, so that the poses `R` and `R F` (same
    /// translation) fit a partial view equally well unless it shows the
    /// small features that tell them apart. One per class of the symmetry
    /// group (`F` and `F S_k` are the same twin). An acquisition checks
    /// them (`spacepose_model::consistency`). Empty for loaded meshes.
    pub fn twins(&self) -> &[Rotation3<f64>] {
        &self.twins
    }

    /// Largest distance of a vertex from the body origin (m).
    pub fn bounding_radius(&self) -> f64 {
        self.bounding_radius
    }

    /// First hit of a ray given in the body frame (see [`Mesh::cast_ray`]).
    #[inline]
    pub fn cast_ray(
        &self,
        origin: &Vector3<f64>,
        dir_unit: &Vector3<f64>,
        max_range: f64,
    ) -> Option<RayHit> {
        self.mesh.cast_ray(origin, dir_unit, max_range)
    }

    /// Model point cloud in the body frame for NDT/ICP: about `area / spacing_m²` points,
    /// spread area-uniformly and deterministically for a given `seed` (see
    /// [`sampling::sample_mesh_surface`]). A non-finite or non-positive spacing, or one that
    /// would give more than [`sampling::MAX_SAMPLES`] points, gives an empty cloud; call
    /// [`sampling::sample_mesh_surface`] to get the error instead.
    pub fn sample_surface(&self, spacing_m: f64, seed: u64) -> Vec<Vector3<f64>> {
        sampling::sample_mesh_surface(&self.mesh, spacing_m, seed).unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box(material: u16) -> Mesh {
        Mesh::cuboid(
            Vector3::zeros(),
            Vector3::new(0.5, 0.5, 0.5),
            Rotation3::identity(),
            material,
        )
    }

    #[test]
    fn target_is_send_sync() {
        fn check<T: Send + Sync + Clone>() {}
        check::<Target>();
    }

    #[test]
    fn new_validates_parts() {
        let mats = vec![Material::default_structure()];
        let id = vec![Rotation3::identity()];
        assert!(Target::new("ok", unit_box(0), mats.clone(), id.clone()).is_ok());
        assert!(Target::new("no-mat", unit_box(1), mats.clone(), id.clone()).is_err());
        assert!(Target::new("no-sym", unit_box(0), mats.clone(), vec![]).is_err());
        let not_first = vec![Rotation3::from_axis_angle(&Vector3::x_axis(), 1.0)];
        assert!(Target::new("sym", unit_box(0), mats.clone(), not_first).is_err());
        let mut bad = mats;
        bad[0].reflectance = 2.0;
        assert!(Target::new("bad", unit_box(0), bad, id).is_err());
    }

    #[test]
    fn resolve_builtins_and_errors() {
        let t = Target::resolve("deos", 1.0).expect("deos");
        assert_eq!(t.name(), "deos");
        let big = Target::resolve("deos", 2.0).expect("deos x2");
        assert!((big.bounding_radius() - 2.0 * t.bounding_radius()).abs() < 1e-9);
        assert_eq!(big.symmetries().len(), 3);
        assert!(matches!(
            Target::resolve("deos", 0.0),
            Err(TargetError::InvalidScale { .. })
        ));
        assert!(matches!(
            Target::builtin("hubble"),
            Err(TargetError::UnknownBuiltin(_))
        ));
        let err = Target::resolve("/nonexistent/dir/model.stl", 1.0).expect_err("missing");
        assert!(err.to_string().contains("/nonexistent/dir/model.stl"));
        for name in Target::BUILTIN {
            let t = Target::builtin(name).expect("builtin");
            assert_eq!(t.name(), *name);
            assert!(t.materials().iter().all(|m| m.validate().is_ok()));
            assert!(t.symmetries()[0].angle() < 1e-12);
        }
    }

    #[test]
    fn sample_surface_rejects_bad_spacing_with_empty_cloud() {
        let t = Target::new(
            "box",
            unit_box(0),
            vec![Material::default_structure()],
            vec![Rotation3::identity()],
        )
        .expect("target");
        assert!(t.sample_surface(0.0, 1).is_empty());
        assert!(t.sample_surface(f64::NAN, 1).is_empty());
        assert!(!t.sample_surface(0.1, 1).is_empty());
    }
}
