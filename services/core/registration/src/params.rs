//! Parameters of the map and of the registration algorithms. `Default` is
//! seed 000 Table 1; `validate()` rejects NaN, infinite and non-positive
//! values.

use crate::error::RegistrationError;
use serde::{Deserialize, Serialize};

/// Fails unless `value` is finite and strictly positive.
pub(crate) fn check_positive(name: &'static str, value: f64) -> Result<(), RegistrationError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(RegistrationError::param(
            name,
            format!("must be finite and > 0, got {value}"),
        ))
    }
}

/// How to build the smoothed NDT map (seed 000 §3.1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NdtMapParams {
    /// Minimal cell size of the kd-tree partition (m): a cell is split (at
    /// the median, along its widest axis) while its points' extent along
    /// that axis exceeds this. Table 1: 7.5 cm.
    pub min_cell_size_m: f64,
    /// A cell is only split when both halves keep at least this many points,
    /// so that every leaf has a usable covariance.
    pub min_points_per_cell: usize,
    /// Standard deviation σ of the Gaussian blur of Eq. (2) (m). The paper
    /// takes it close to the minimal cell size.
    pub smoothing_sigma_m: f64,
    /// Smoothing radius in units of σ (the paper uses 3σ).
    pub smoothing_radius_sigmas: f64,
    /// Relative eigenvalue floor: every covariance eigenvalue is raised to at
    /// least `eigen_floor_rel · λ_max` (planar CAD faces are degenerate).
    pub eigen_floor_rel: f64,
    /// Absolute floor on the standard deviation along any axis of a cell
    /// (m): eigenvalues are raised to at least its square.
    pub eigen_floor_abs_m: f64,
    /// Maximum point-to-cell distance the precomputed lookup grid serves
    /// exactly (m); should equal [`NdtParams::max_distance_m`]. Table 1:
    /// 7.5 cm.
    pub lookup_max_distance_m: f64,
    /// Edge of a lookup-grid voxel (m). Coarsened automatically when the
    /// grid would exceed [`NdtMapParams::max_lookup_voxels`].
    pub lookup_resolution_m: f64,
    /// Upper bound on the number of lookup-grid voxels (memory guard).
    pub max_lookup_voxels: usize,
}

impl Default for NdtMapParams {
    fn default() -> Self {
        Self {
            min_cell_size_m: 0.075,
            min_points_per_cell: 5,
            smoothing_sigma_m: 0.075,
            smoothing_radius_sigmas: 3.0,
            eigen_floor_rel: 0.01,
            eigen_floor_abs_m: 0.002,
            lookup_max_distance_m: 0.075,
            lookup_resolution_m: 0.0375,
            max_lookup_voxels: 1 << 25,
        }
    }
}

impl NdtMapParams {
    /// Rejects NaN, infinite, non-positive or out-of-domain values.
    pub fn validate(&self) -> Result<(), RegistrationError> {
        check_positive("min_cell_size_m", self.min_cell_size_m)?;
        check_positive("smoothing_sigma_m", self.smoothing_sigma_m)?;
        check_positive("smoothing_radius_sigmas", self.smoothing_radius_sigmas)?;
        check_positive("eigen_floor_rel", self.eigen_floor_rel)?;
        check_positive("eigen_floor_abs_m", self.eigen_floor_abs_m)?;
        check_positive("lookup_max_distance_m", self.lookup_max_distance_m)?;
        check_positive("lookup_resolution_m", self.lookup_resolution_m)?;
        if self.eigen_floor_rel >= 1.0 {
            return Err(RegistrationError::param("eigen_floor_rel", "must be < 1"));
        }
        if self.min_points_per_cell == 0 {
            return Err(RegistrationError::param(
                "min_points_per_cell",
                "must be >= 1",
            ));
        }
        if self.max_lookup_voxels < 8 {
            return Err(RegistrationError::param(
                "max_lookup_voxels",
                "must be >= 8",
            ));
        }
        Ok(())
    }
}

/// How to find the cell η(i) associated with a transformed point (NDT),
/// or the nearest model point (ICP, [`IcpParams::lookup`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum CellLookup {
    /// The map's precomputed voxel grid of candidate cells (exact nearest
    /// mean within the grid's maximum distance). Falls back to the kd-tree
    /// when [`NdtParams::max_distance_m`] exceeds the distance the grid was
    /// built for.
    #[default]
    Grid,
    /// A kiddo kd-tree over the smoothed cell means (exact nearest mean).
    KdTree,
}

/// Gauss-Newton NDT and CT-NDT registration (seed 000 §3.1, §3.3, Table 1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NdtParams {
    /// Maximum distance between a transformed point and the mean of its
    /// nearest cell for the pair to enter the cost (m). Table 1: 7.5 cm.
    pub max_distance_m: f64,
    /// Maximum number of Gauss-Newton increments. Table 1: 20.
    pub max_iterations: usize,
    /// Convergence: the rotation part of the increment is below this (deg)…
    /// Table 1: 0.05°.
    pub termination_rotation_deg: f64,
    /// …and the translation part is below this (m). Table 1: 1 mm.
    pub termination_translation_m: f64,
    /// Nearest-cell search structure.
    pub lookup: CellLookup,
    /// Speed-up, not in the paper: the first Gauss-Newton increments use
    /// only every `coarse_stride`-th point (1 disables the coarse phase).
    pub coarse_stride: usize,
    /// The coarse phase ends once an increment is below this multiple of
    /// the termination thresholds; later iterations and the convergence
    /// test use every point.
    pub coarse_switch: f64,
    /// Degeneracy handling of `register_ndt`, not in seed 000 (after the
    /// "solution remapping" of Zhang, Kaess and Singh, ICRA 2016). Before
    /// the Gauss-Newton loop, the *geometric* information at the initial
    /// pose, `Σ Jᵀ n nᵀ J` with `n` the normal of each point's cell (what
    /// the surface constrains, point-to-plane), gives the rotation
    /// information with the translation marginalised out. A rotation axis
    /// whose mean squared lever arm (eigenvalue over points) is below this
    /// squared gets no increment: the pose keeps the initial guess there
    /// (the filter prediction in `deblur` mode). NDT's own information is
    /// no guide: its cells have a finite extent along the surface, so a
    /// plane seems to constrain turning within itself and pulls the points
    /// toward the cell means. Seen end-on at 3 m, deos shows a plane and a
    /// cylinder (its MLI face and tower): the roll about the tower is then
    /// unobservable, and NDT held it still while the target spun. 0
    /// disables it (the paper).
    #[serde(default)]
    pub min_lever_arm_m: f64,
    /// The translation half of the degeneracy handling (issue 25 item 4;
    /// not in seed 000): with the rotations that are not held free, a
    /// translation whose RMS cosine with the surface normals is below
    /// this gets no increment, and keeps the initial guess along it
    /// together with the turn that keeps the surface fitted
    /// ([`crate::weak_directions`]). Dimensionless, so the same for every
    /// target. 0 disables it (the paper).
    #[serde(default)]
    pub min_translation_cosine: f64,
}

impl Default for NdtParams {
    fn default() -> Self {
        Self {
            max_distance_m: 0.075,
            max_iterations: 20,
            termination_rotation_deg: 0.05,
            termination_translation_m: 0.001,
            lookup: CellLookup::Grid,
            coarse_stride: 4,
            coarse_switch: 5.0,
            min_lever_arm_m: 0.0,
            min_translation_cosine: 0.0,
        }
    }
}

impl NdtParams {
    /// True when either half of the degeneracy handling is on, so the
    /// geometric information is computed.
    pub fn handles_degeneracy(&self) -> bool {
        self.min_lever_arm_m > 0.0 || self.min_translation_cosine > 0.0
    }

    /// Rejects NaN, infinite, non-positive or out-of-domain values.
    pub fn validate(&self) -> Result<(), RegistrationError> {
        check_positive("max_distance_m", self.max_distance_m)?;
        check_positive("termination_rotation_deg", self.termination_rotation_deg)?;
        check_positive("termination_translation_m", self.termination_translation_m)?;
        check_positive("coarse_switch", self.coarse_switch)?;
        if !(self.min_lever_arm_m.is_finite() && self.min_lever_arm_m >= 0.0) {
            return Err(RegistrationError::param(
                "min_lever_arm_m",
                "must be finite and >= 0",
            ));
        }
        if !(self.min_translation_cosine.is_finite()
            && (0.0..1.0).contains(&self.min_translation_cosine))
        {
            return Err(RegistrationError::param(
                "min_translation_cosine",
                "must be finite, >= 0 and < 1",
            ));
        }
        if self.max_iterations == 0 {
            return Err(RegistrationError::param("max_iterations", "must be >= 1"));
        }
        if self.coarse_stride == 0 {
            return Err(RegistrationError::param("coarse_stride", "must be >= 1"));
        }
        Ok(())
    }
}

/// Point-to-point ICP (seed 000 Table 1, ICP row).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IcpParams {
    /// Maximum point-to-point correspondence distance (m). Table 1: 10 cm.
    pub max_distance_m: f64,
    /// Maximum number of iterations. Table 1: 40.
    pub max_iterations: usize,
    /// Convergence when the norm of the increment `[Log ΔR; Δp]` (rad, m)
    /// drops below this. Table 1: 1e-6.
    pub termination_increment: f64,
    /// Standard deviation of the point-to-point residual along each axis
    /// (m), used to scale the information matrix `Σ JᵀJ / σ²`.
    pub point_sigma_m: f64,
    /// Nearest-model-point search: [`CellLookup::Grid`] is the model's
    /// precomputed voxel grid of candidate points (exact within the
    /// distance it was built for, kd-tree beyond), [`CellLookup::KdTree`]
    /// the kiddo kd-tree alone. Both give the same pairs.
    #[serde(default)]
    pub lookup: CellLookup,
    /// Wide searches go approximate (not in seed 000): when set, and
    /// `max_distance_m` is at least this, the iterations pair points
    /// through the model's far lookup if it has one
    /// ([`crate::IcpModel::with_far_lookup`]: the answer is at most about
    /// 2 voxel edges farther than the nearest model point), and so does
    /// the final evaluation (cost, f_CONV, information), which is then
    /// approximate too: meant for stages whose result only feeds a
    /// narrower one. `None` (default): exact pairs.
    #[serde(default)]
    pub far_lookup_from_m: Option<f64>,
}

impl Default for IcpParams {
    fn default() -> Self {
        Self {
            max_distance_m: 0.10,
            max_iterations: 40,
            termination_increment: 1e-6,
            point_sigma_m: 0.01,
            lookup: CellLookup::Grid,
            far_lookup_from_m: None,
        }
    }
}

impl IcpParams {
    /// Rejects NaN, infinite, non-positive or out-of-domain values.
    pub fn validate(&self) -> Result<(), RegistrationError> {
        check_positive("max_distance_m", self.max_distance_m)?;
        check_positive("termination_increment", self.termination_increment)?;
        check_positive("point_sigma_m", self.point_sigma_m)?;
        if let Some(from) = self.far_lookup_from_m {
            check_positive("far_lookup_from_m", from)?;
        }
        if self.max_iterations == 0 {
            return Err(RegistrationError::param("max_iterations", "must be >= 1"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_table_1_and_valid() {
        let m = NdtMapParams::default();
        assert_eq!(m.min_cell_size_m, 0.075);
        m.validate().unwrap();
        let n = NdtParams::default();
        assert_eq!((n.max_distance_m, n.max_iterations), (0.075, 20));
        assert_eq!(
            (n.termination_rotation_deg, n.termination_translation_m),
            (0.05, 0.001)
        );
        n.validate().unwrap();
        let i = IcpParams::default();
        assert_eq!(
            (i.max_distance_m, i.max_iterations, i.termination_increment),
            (0.1, 40, 1e-6)
        );
        i.validate().unwrap();
    }

    #[test]
    fn nan_and_non_positive_are_rejected() {
        let m = NdtMapParams {
            smoothing_sigma_m: f64::NAN,
            ..Default::default()
        };
        assert!(m.validate().is_err());
        let m = NdtMapParams {
            min_cell_size_m: 0.0,
            ..Default::default()
        };
        assert!(m.validate().is_err());
        let n = NdtParams {
            max_distance_m: f64::NAN,
            ..Default::default()
        };
        assert!(n.validate().is_err());
        let n = NdtParams {
            termination_translation_m: -1.0,
            ..Default::default()
        };
        assert!(n.validate().is_err());
        let n = NdtParams {
            max_iterations: 0,
            ..Default::default()
        };
        assert!(n.validate().is_err());
        let i = IcpParams {
            point_sigma_m: f64::INFINITY,
            ..Default::default()
        };
        assert!(i.validate().is_err());
        let i = IcpParams {
            termination_increment: f64::NAN,
            ..Default::default()
        };
        assert!(i.validate().is_err());
    }
}
