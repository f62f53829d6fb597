//! `target.toml`: what a package records (serde, `deny_unknown_fields`).

use crate::error::TargetError;
use crate::material::{Material, MaterialClass};
use nalgebra::{Rotation3, Vector3};
use serde::{Deserialize, Serialize};

/// Version of the package layout; a package of another format is refused.
pub const PACKAGE_FORMAT: u32 = 1;

/// The manifest of a target package (`target.toml`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PackageManifest {
    /// [`PACKAGE_FORMAT`] when written.
    pub format: u32,
    /// Name of the target (used in logs and telemetry).
    pub name: String,
    /// Where the mesh came from and its conventions.
    pub mesh: MeshRecord,
    /// One entry per material id used by the mesh's faces.
    pub materials: Vec<MaterialRecord>,
    /// Geometry derived from the mesh.
    pub geometry: Geometry,
    /// Symmetry group and near-symmetric twins.
    pub symmetry: SymmetryRecord,
    /// Per-target thresholds calibrated from simulated frames.
    pub calibration: Calibration,
    /// How the package was made, so that it can be rebuilt.
    pub provenance: Provenance,
}

/// The mesh file and its conventions.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshRecord {
    /// The mesh in the package (relative to the package directory).
    pub file: String,
    /// The source: a mesh path as given, or `builtin:<name>`.
    pub source: String,
    /// Scale applied to the source's coordinates to get metres.
    pub source_scale: f64,
    /// Where the body origin (the centre of mass) lies in the scaled source
    /// frame (m): the package mesh is the source mesh moved by minus this.
    pub origin_in_source_m: [f64; 3],
    /// The frame convention in words.
    pub conventions: String,
}

/// A material of the package (see [`Material`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialRecord {
    /// Name.
    pub name: String,
    /// `structure`, `aluminium`, `solar-panel` or `mli`.
    pub class: String,
    /// ρ_T of seed 002 Eq. (6).
    pub reflectance: f64,
    /// Seed 004 Table I k_d range.
    pub kd_range: [f64; 2],
    /// Seed 004 Table I η range.
    pub eta_range: [f64; 2],
}

/// Geometry derived from the mesh (body frame, metres).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Geometry {
    /// Largest distance of a vertex from the centre of mass.
    pub bounding_radius_m: f64,
    /// Lower corner of the body-frame bounding box.
    pub body_box_min_m: [f64; 3],
    /// Upper corner of the body-frame bounding box.
    pub body_box_max_m: [f64; 3],
    /// Size of the body box along x, y, z.
    pub extent_m: [f64; 3],
    /// Surface area (m²).
    pub surface_area_m2: f64,
    /// Triangle count.
    pub triangles: usize,
}

/// The symmetry group and twins, as rotation vectors (axis × angle, rad).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SymmetryRecord {
    /// Rotations `S_k` with `Q ≡ Q S_k` (seed 004 Eq. (14)), identity first.
    pub group_rotvec_rad: Vec<[f64; 3]>,
    /// Near-symmetric twins, one per coset of the group.
    pub twins_rotvec_rad: Vec<[f64; 3]>,
    /// `detected` (from the mesh), `declared` (a built-in's own list) or
    /// `override` (given by the user).
    pub source: String,
    /// Surface-distance tolerance of the detection, as a fraction of the
    /// bounding radius.
    pub tolerance_fraction: f64,
}

/// Per-target thresholds, calibrated by simulating this target with every
/// sensor effect on (truth is used at prepare time only, never at run time).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Calibration {
    /// Largest mean NDT cost per inlier of a usable registration
    /// (Mahalanobis, unitless): tracker `loss.max_mean_cost_ndt`.
    pub max_mean_cost_ndt: f64,
    /// Smallest fraction of the filtered points that must find a cell:
    /// tracker `loss.min_inlier_fraction`.
    pub min_inlier_fraction: f64,
    /// The target's NDT length unit ℓ (m): max(7.5 cm, 0.018 √A) with A
    /// the surface area; the tracker's map and loop lengths are given for
    /// 7.5 cm and multiplied by ℓ / 7.5 cm (`spacepose_tracker::length_unit`).
    pub length_unit_m: f64,
    /// The figures the thresholds were derived from.
    pub record: CalibrationRecord,
}

/// How a [`Calibration`] was derived.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationRecord {
    /// Simulated frames registered.
    pub frames: usize,
    /// Frames whose registration was within the "well registered" bound
    /// and so entered the statistics.
    pub frames_used: usize,
    /// Scenario seeds (calibration seeds, never evaluation seeds).
    pub seeds: Vec<u64>,
    /// Sensor-to-target ranges simulated (m).
    pub ranges_m: Vec<f64>,
    /// Median mean cost per inlier.
    pub mean_cost_p50: f64,
    /// 99th percentile of the mean cost per inlier.
    pub mean_cost_p99: f64,
    /// 1st percentile of the inlier fraction.
    pub inlier_fraction_p01: f64,
    /// The margins applied, in words.
    pub rule: String,
}

/// How a package was made.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Provenance {
    /// `spacepose` version that wrote it.
    pub spacepose_version: String,
    /// The command that rebuilds it.
    pub command: String,
    /// FNV-1a 64 of the source mesh bytes (hex; not cryptographic: it keys
    /// the on-the-fly cache and detects a changed source).
    pub source_fnv64: String,
    /// Seconds the preparation took.
    pub prepare_s: f64,
}

impl PackageManifest {
    /// The manifest of `target` (its name, materials and geometry are read
    /// from it) with the given records.
    pub fn describe(
        target: &crate::target::Target,
        mesh: MeshRecord,
        symmetry: SymmetryRecord,
        calibration: Calibration,
        provenance: Provenance,
    ) -> PackageManifest {
        PackageManifest {
            format: PACKAGE_FORMAT,
            name: target.name().to_owned(),
            mesh,
            materials: target.materials().iter().map(MaterialRecord::of).collect(),
            geometry: Geometry::of(target.mesh()),
            symmetry,
            calibration,
            provenance,
        }
    }
}

impl SymmetryRecord {
    /// The record of a group and twins.
    pub fn of(
        group: &[Rotation3<f64>],
        twins: &[Rotation3<f64>],
        source: &str,
        tolerance_fraction: f64,
    ) -> SymmetryRecord {
        SymmetryRecord {
            group_rotvec_rad: group.iter().map(rotvec_of).collect(),
            twins_rotvec_rad: twins.iter().map(rotvec_of).collect(),
            source: source.to_owned(),
            tolerance_fraction,
        }
    }

    /// The group as rotations.
    pub fn group(&self) -> Vec<Rotation3<f64>> {
        self.group_rotvec_rad.iter().map(rotation_of).collect()
    }

    /// The twins as rotations.
    pub fn twins(&self) -> Vec<Rotation3<f64>> {
        self.twins_rotvec_rad.iter().map(rotation_of).collect()
    }
}

/// A rotation as its rotation vector (rad).
fn rotvec_of(r: &Rotation3<f64>) -> [f64; 3] {
    // Through the quaternion: `Rotation3::scaled_axis` gives zero at π.
    let v = nalgebra::UnitQuaternion::from_rotation_matrix(r).scaled_axis();
    [v.x, v.y, v.z]
}

fn rotation_of(v: &[f64; 3]) -> Rotation3<f64> {
    Rotation3::new(Vector3::from(*v))
}

impl MaterialRecord {
    /// The record of a material.
    pub fn of(m: &Material) -> MaterialRecord {
        let class = match m.class {
            MaterialClass::Structure => "structure",
            MaterialClass::Aluminium => "aluminium",
            MaterialClass::SolarPanel => "solar-panel",
            MaterialClass::Mli => "mli",
        };
        MaterialRecord {
            name: m.name.clone(),
            class: class.to_owned(),
            reflectance: m.reflectance,
            kd_range: m.kd_range,
            eta_range: m.eta_range,
        }
    }

    /// The material; an unknown class is an error naming it.
    pub fn material(&self) -> Result<Material, TargetError> {
        let class = match self.class.as_str() {
            "structure" => MaterialClass::Structure,
            "aluminium" => MaterialClass::Aluminium,
            "solar-panel" => MaterialClass::SolarPanel,
            "mli" => MaterialClass::Mli,
            other => {
                return Err(TargetError::InvalidPackage(format!(
                    "material '{}': unknown class '{other}'",
                    self.name
                )));
            }
        };
        let m = Material {
            name: self.name.clone(),
            class,
            reflectance: self.reflectance,
            kd_range: self.kd_range,
            eta_range: self.eta_range,
        };
        m.validate().map_err(TargetError::InvalidPackage)?;
        Ok(m)
    }
}

impl Calibration {
    /// Fails on a non-finite or out-of-range threshold.
    pub fn validate(&self) -> Result<(), TargetError> {
        let c = self;
        if !(c.max_mean_cost_ndt.is_finite() && c.max_mean_cost_ndt > 0.0) {
            return Err(TargetError::InvalidPackage(format!(
                "calibration.max_mean_cost_ndt = {} must be finite and > 0",
                c.max_mean_cost_ndt
            )));
        }
        if !(c.length_unit_m.is_finite() && c.length_unit_m > 0.0) {
            return Err(TargetError::InvalidPackage(format!(
                "calibration.length_unit_m = {} must be finite and > 0",
                c.length_unit_m
            )));
        }
        if !(c.min_inlier_fraction.is_finite() && (0.0..=1.0).contains(&c.min_inlier_fraction)) {
            return Err(TargetError::InvalidPackage(format!(
                "calibration.min_inlier_fraction = {} must be in [0, 1]",
                c.min_inlier_fraction
            )));
        }
        Ok(())
    }
}

impl Geometry {
    /// The geometry of a body-frame mesh.
    pub fn of(mesh: &crate::mesh::Mesh) -> Geometry {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut radius: f64 = 0.0;
        for v in mesh.vertices() {
            for i in 0..3 {
                lo[i] = lo[i].min(v[i]);
                hi[i] = hi[i].max(v[i]);
            }
            radius = radius.max(v.norm());
        }
        Geometry {
            bounding_radius_m: radius,
            body_box_min_m: lo,
            body_box_max_m: hi,
            extent_m: [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]],
            surface_area_m2: mesh.surface_area(),
            triangles: mesh.triangle_count(),
        }
    }
}
