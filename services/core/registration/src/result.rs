//! What every registration returns: never just a pose.

use nalgebra::Matrix6;
use spacepose_geometry::Pose;

/// Value of the cost function at the returned pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cost {
    /// Sum over the inliers (NDT: Mahalanobis terms of Eq. 3 / 14, unitless;
    /// ICP: squared point-to-point distances, m²).
    pub total: f64,
    /// `total / inliers` (0 without inliers).
    pub mean: f64,
}

/// The last increment applied, split as in the termination test.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Increment {
    /// Rotation angle `|ε₁:₃|` (rad).
    pub rotation_rad: f64,
    /// Translation `|ε₄:₆|` (m).
    pub translation_m: f64,
}

/// The outcome of one registration.
///
/// Pose convention: registration aligns the source cloud (sensor frame) with
/// the model (target body frame), so the estimate is `t_target_sensor`,
/// mapping sensor coordinates into the target frame (`T` of seed 000 Eq. 3).
/// [`Registration::t_sensor_target`] gives the inverse the tracker reports.
#[derive(Debug, Clone, PartialEq)]
pub struct Registration {
    /// The estimate `T` (sensor → target body). For the continuous-time
    /// NDT, the pose at the end of the scan, `T^e`.
    pub t_target_sensor: Pose,
    /// True when the termination test of the increment was met before the
    /// iteration limit.
    pub converged: bool,
    /// Number of increments computed (Gauss-Newton steps or ICP updates).
    pub iterations: usize,
    /// Cost at the returned pose.
    pub cost: Cost,
    /// Points with a correspondence at the returned pose.
    pub inliers: usize,
    /// Finite points of the source cloud (inliers + points without a
    /// correspondence).
    pub valid_points: usize,
    /// Points skipped because a coordinate (or, for CT-NDT, the timestamp)
    /// was not finite.
    pub skipped_non_finite: usize,
    /// Mean squared Euclidean distance between the transformed inliers and
    /// their correspondences (cell means for NDT, model points for ICP), m².
    pub mean_squared_distance_m2: f64,
    /// ICP only: `f_CONV` of seed 002 §4.5, the mean squared distance from
    /// every valid transformed point to its nearest model point, without
    /// any distance cut (m²). Millimetres² when aligned; `None` for NDT.
    pub f_conv_m2: Option<f64>,
    /// `Σ Jᵀ C⁻¹ J` at the returned pose, for the left perturbation
    /// `δ = [rot; trans]` of `t_target_sensor` (seed 000 Eq. 5). For ICP,
    /// `Σ JᵀJ / σ²` with [`crate::IcpParams::point_sigma_m`].
    pub information: Matrix6<f64>,
    /// The last increment.
    pub last_increment: Increment,
    /// Rotation axes left at the initial guess as unobservable
    /// (`NdtParams::min_lever_arm_m`; 0 when off, for CT-NDT and ICP).
    pub degenerate_directions: usize,
    /// The weakest rotation's lever arm in the geometric information at the
    /// initial pose (m; NaN when not computed: degeneracy handling off,
    /// CT-NDT, ICP). Near 0: a rotation the surface does not constrain.
    pub weakest_lever_arm_m: f64,
    /// Translations left at the initial guess as weakly constrained
    /// (`NdtParams::min_translation_cosine`; 0 when off and for ICP).
    pub held_translations: usize,
    /// The weakest translation's RMS cosine with the surface normals, the
    /// rotations that were not held free, at the initial pose (NaN when
    /// not computed). Near 0: a shift the surface hardly constrains.
    pub weakest_translation_cosine: f64,
    /// The geometric (point-to-plane) information `Σ Jᵀ n nᵀ J` at the
    /// initial pose, for a unit point noise, when the degeneracy handling
    /// computed it: what the surface in view constrains, unlike
    /// `information`, which also counts NDT's pull toward cell means.
    pub geometric_information: Option<Matrix6<f64>>,
}

impl Registration {
    /// The estimate as `t_sensor_target` (target body → sensor), the
    /// inverse of [`Registration::t_target_sensor`].
    pub fn t_sensor_target(&self) -> Pose {
        self.t_target_sensor.inverse()
    }

    /// Fraction of the valid points that found a correspondence.
    pub fn inlier_fraction(&self) -> f64 {
        if self.valid_points == 0 {
            0.0
        } else {
            self.inliers as f64 / self.valid_points as f64
        }
    }
}
