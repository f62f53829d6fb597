//! `spacepose target prepare`: a mesh or a built-in target into a package.

use crate::calibrate::{CalibrationOptions, calibrate};
use crate::error::PrepareError;
use crate::fnv::{OFFSET, fnv1a64};
use nalgebra::{Rotation3, Vector3};
use spacepose_model::Target;
use spacepose_model::package::{
    MESH_FILE, MeshRecord, PackageManifest, Provenance, SymmetryRecord, TargetPackage,
    write_package,
};
use spacepose_model::symmetry::{SymmetryOptions, detect_symmetries};
use spacepose_tracker::{REFERENCE_LENGTH_M, TargetThresholds, TrackingModel, map_params_scaled};
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// Where the symmetry group comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum SymmetryChoice {
    /// Detected from the mesh (the default).
    Detect(SymmetryOptions),
    /// Given by the user (identity first), with twins.
    Override {
        /// The group, identity first.
        group: Vec<Rotation3<f64>>,
        /// The twins.
        twins: Vec<Rotation3<f64>>,
    },
}

/// What [`prepare`] does.
#[derive(Clone, Debug, PartialEq)]
pub struct PrepareOptions {
    /// Name of the target (default: the built-in name or the file stem).
    pub name: Option<String>,
    /// Scale from the file's units to metres (1.0 for built-ins).
    pub scale: f64,
    /// Symmetry detection or override.
    pub symmetry: SymmetryChoice,
    /// The calibration's frames.
    pub calibration: CalibrationOptions,
    /// Spacing of the model cloud the tracker samples (m) for the
    /// reference cell: the tracker service's `model_spacing_m` default, so
    /// that the calibration sees the map the tracker will build (both scale
    /// it by ℓ / 7.5 cm).
    pub model_spacing_m: f64,
    /// The command line that made the package (recorded to rebuild it).
    pub command: String,
}

impl Default for PrepareOptions {
    fn default() -> Self {
        PrepareOptions {
            name: None,
            scale: 1.0,
            symmetry: SymmetryChoice::Detect(SymmetryOptions::default()),
            calibration: CalibrationOptions::default(),
            model_spacing_m: 0.015,
            command: String::new(),
        }
    }
}

/// Prepares `spec` (a built-in name, a mesh file, or `zoo:N` for the
/// generated target of seed N) into a package and
/// writes it to `out` when given; `progress(done, total)` follows the
/// calibration.
pub fn prepare(
    spec: &str,
    options: &PrepareOptions,
    out: Option<&Path>,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<TargetPackage, PrepareError> {
    let started = Instant::now();
    let (target, mesh_record, fnv) = load_source(spec, options.scale)?;
    let name = options
        .name
        .clone()
        .unwrap_or_else(|| target.name().to_owned());
    let (group, twins, symmetry) = symmetry_of(&target, &options.symmetry)?;
    let target = Arc::new(target.with_symmetries(&name, group, twins)?);
    let factor = length_unit_m(target.mesh().surface_area()) / REFERENCE_LENGTH_M;
    let cloud = target.sample_surface(options.model_spacing_m * factor, 0);
    if cloud.is_empty() {
        return Err(PrepareError::InvalidOption(format!(
            "model_spacing_m = {} gives no model cloud for this mesh",
            options.model_spacing_m
        )));
    }
    let thresholds = TargetThresholds {
        length_scale: factor,
        ..TargetThresholds::UNCALIBRATED
    };
    let model =
        TrackingModel::build(&cloud, &map_params_scaled(factor))?.with_thresholds(thresholds);
    let calibration = calibrate(&target, &model, &options.calibration, progress)?;
    let provenance = Provenance {
        spacepose_version: env!("CARGO_PKG_VERSION").to_owned(),
        command: options.command.clone(),
        source_fnv64: format!("{fnv:016x}"),
        prepare_s: started.elapsed().as_secs_f64(),
    };
    let manifest =
        PackageManifest::describe(&target, mesh_record, symmetry, calibration, provenance);
    let target = Arc::unwrap_or_clone(target);
    if let Some(dir) = out {
        write_package(dir, &target, &manifest)?;
    }
    Ok(TargetPackage {
        target,
        manifest,
        dir: out.map(Path::to_owned),
    })
}

/// The target's NDT length unit ℓ (m) from its surface area `A` (m²):
/// max(7.5 cm, 0.018 √A). Seed 000 Table 1's 7.5 cm cell serves a
/// deos-sized body (17 m², 0.018 √A = 7.4 cm); a larger one keeps about as
/// many cells across its surface (√A / ℓ ≈ 55), so the basin of the
/// registration stays the same fraction of the target.
pub fn length_unit_m(surface_area_m2: f64) -> f64 {
    (0.018 * surface_area_m2.max(0.0).sqrt()).max(REFERENCE_LENGTH_M)
}

/// The target, its mesh record and the FNV-1a of its source.
pub(crate) fn load_source(
    spec: &str,
    scale: f64,
) -> Result<(Target, MeshRecord, u64), PrepareError> {
    let record = |source: String, origin: Vector3<f64>, conventions: &str| MeshRecord {
        file: MESH_FILE.to_owned(),
        source,
        source_scale: scale,
        origin_in_source_m: [origin.x, origin.y, origin.z],
        conventions: conventions.to_owned(),
    };
    if Target::BUILTIN.contains(&spec) {
        let target = Target::resolve(spec, scale)?;
        let source = format!("builtin:{spec}");
        let fnv = fnv1a64(fnv1a64(OFFSET, source.as_bytes()), &scale.to_le_bytes());
        let r = record(
            source,
            Vector3::zeros(),
            "built-in body frame (see spacepose_model::builtin)",
        );
        return Ok((target, r, fnv));
    }
    if let Some(seed) = zoo_seed(spec)? {
        if scale != 1.0 {
            return Err(PrepareError::InvalidOption(format!(
                "{spec}: a generated target is in metres; scale {scale} applies to mesh files only"
            )));
        }
        let zoo = spacepose_model::zoo::generate(seed)?;
        let source = format!("zoo:{seed}:v{}", spacepose_model::zoo::ZOO_VERSION);
        let fnv = fnv1a64(OFFSET, source.as_bytes());
        let r = record(source, Vector3::zeros(), &zoo.description);
        return Ok((zoo.target, r, fnv));
    }
    let path = Path::new(spec);
    let bytes = std::fs::read(path).map_err(|e| PrepareError::Io {
        path: path.to_owned(),
        message: e.to_string(),
    })?;
    let fnv = fnv1a64(fnv1a64(OFFSET, &bytes), &scale.to_le_bytes());
    let (target, origin) = Target::load_with_origin(path, scale)?;
    let conventions = "file axes; file units x source_scale = metres; origin moved to the \
                       area-weighted surface centroid (centre of mass of a uniform shell)";
    Ok((target, record(spec.to_owned(), origin, conventions), fnv))
}

/// The seed of a generated target's spec `zoo:N` (`None` for any other
/// spec; an error for `zoo:` followed by something else than a number).
fn zoo_seed(spec: &str) -> Result<Option<u64>, PrepareError> {
    let Some(rest) = spec.strip_prefix("zoo:") else {
        return Ok(None);
    };
    rest.parse().map(Some).map_err(|_| {
        PrepareError::InvalidOption(format!(
            "{spec:?}: a generated target is `zoo:N`, N a seed (a whole number)"
        ))
    })
}

/// A symmetry group, its twins, and their record.
type Symmetry = (Vec<Rotation3<f64>>, Vec<Rotation3<f64>>, SymmetryRecord);

/// The group, twins and their record.
fn symmetry_of(target: &Target, choice: &SymmetryChoice) -> Result<Symmetry, PrepareError> {
    match choice {
        SymmetryChoice::Detect(options) => {
            let report = detect_symmetries(target.mesh(), options)?;
            let record = SymmetryRecord::of(
                &report.group,
                &report.twins,
                "detected",
                options.tolerance_fraction,
            );
            Ok((report.group, report.twins, record))
        }
        SymmetryChoice::Override { group, twins } => {
            let record = SymmetryRecord::of(group, twins, "override", 0.0);
            Ok((group.clone(), twins.clone(), record))
        }
    }
}
