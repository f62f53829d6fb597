//! Tracker configuration: one serde struct, defaults from seed 000 Table 1.

use crate::error::TrackError;
use crate::held_rotation::HeldRotationConfig;
pub use crate::loss::LossConfig;
use crate::mode::TrackingMode;
use crate::visibility::VisibilityConfig;
use serde::{Deserialize, Serialize};
use spacepose_filter::FilterConfig;
use spacepose_registration::{IcpParams, NdtParams};

/// Everything the tracking loop needs to know.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrackerConfig {
    /// Tracking mode.
    pub mode: TrackingMode,
    /// Voxel filter leaf size (m). Table 1: 2 cm.
    pub voxel_leaf_m: f64,
    /// NDT registration parameters (Table 1), plus the degeneracy handling
    /// `min_lever_arm_m` (not in the paper; default 3.5 cm here): a rotation
    /// the surface in view does not constrain is held at the filter's
    /// prediction instead of being pulled around by NDT's cells. On
    /// `spacepose eval tracking --seed 7`, the weakest rotation's lever arm
    /// is 5-25 cm on nearly every frame and falls to 1.2-2 cm at the 3 m
    /// hold (deos end-on: the MLI face and the tower, roll unobservable);
    /// with 3.5 cm the max error of `deblur` went 5.25 → 1.47° (slow-spin)
    /// and 22.5 → 4.3° (tumbling, after warm-up), `ct-ndt` 5.72 → 3.05°
    /// (slow-spin); 2.5 cm gave 2.59° (slow-spin deblur).
    pub ndt: NdtParams,
    /// Hysteresis of the degeneracy handling (m): after a frame that held
    /// a rotation, the next frame holds rotations whose lever arm is below
    /// this instead of `ndt.min_lever_arm_m`. Near the threshold the
    /// handling otherwise toggles from frame to frame and each released
    /// frame lets NDT's cells drag the roll. Equal to (or below)
    /// `ndt.min_lever_arm_m`: no hysteresis.
    pub release_lever_arm_m: f64,
    /// `ndt.min_lever_arm_m` in `ndt` mode (m). That mode has no motion
    /// model: its guess is the previous pose, so at a lever arm of 3.5-5 cm
    /// (the approach to the 3 m hold) NDT's cells drag the roll frame after
    /// frame, where the other modes start from the filter's prediction.
    /// Tuned on slow-spin seed 1 (`ndt` max 9.93° at 3.5 cm, 3.37° at 4.5
    /// and 5 cm, diverged at 5.5 cm, the held rotation's own
    /// `min_lever_arm_m`, at frame 1046); 5 cm.
    pub ndt_mode_min_lever_arm_m: f64,
    /// `ndt.min_lever_arm_m` in `icp` mode (m): ICP's Hessian is that of
    /// the points, so the rotations the surface leaves free are found from
    /// the NDT map's normals ([`spacepose_registration::hold_weak_directions`])
    /// and held at the filter's prediction (then moved onto the fitted
    /// rate, as in the other modes). From the previous pose, nearest
    /// neighbours drag the roll from a lever arm of about 5.4 cm (slow-spin,
    /// approaching the 3 m hold). See [`DEFAULT_ICP_MODE_MIN_LEVER_ARM_M`].
    pub icp_mode_min_lever_arm_m: f64,
    /// The rate a held rotation follows (see [`crate::held_rotation`]):
    /// fitted over the track before the hold instead of the filter's.
    pub held_rotation: HeldRotationConfig,
    /// ICP parameters (Table 1).
    pub icp: IcpParams,
    /// Point noise (m) of the geometric measurement covariance: when the
    /// registration reports its geometric information (with a positive
    /// `ndt.min_lever_arm_m`), the filter's measurement covariance is
    /// `σ² (Σ Jᵀ n nᵀ J)⁻¹` (lightly regularised), so a rotation the surface
    /// hardly constrains is hardly measured. 0 (default): NDT's own
    /// information (the paper's Eq. 7 Hessian). Measured on seed 11
    /// slow-spin (deblur max 9.33 → 3.64°) and seed 7 tumbling (4.33 →
    /// 19.8°): the filter's tuning assumes NDT's information.
    pub geometric_sigma_m: f64,
    /// Start pose of the `ct-ndt` scan (see [`CtStart`]).
    pub ct_start: CtStart,
    /// In `ct-ndt` mode, the attitude block of the measurement covariance
    /// the filter fuses is multiplied by this (1 = NDT's information as
    /// is). Why: CT-NDT's end pose is extrapolated from the scan, and with
    /// its Hessian as the covariance the filter's angular velocity followed
    /// the frame-to-frame noise (±0.1-0.3°/s about the spin); one frame with
    /// a weak roll constraint shifted it by 0.75°/s, and the roll drifted
    /// at that rate once unobservable. Tuned on seed 1 (tumbling) over 1,
    /// 10, 30, 100, 300 (ct-ndt max after warm-up 57.1, 10.0, 7.3°, lost,
    /// lost; the position was scaled with it then, which `deblur` did not
    /// survive on seeds 1 or 11, hence attitude only and ct-ndt only).
    /// Default 1 since the motion prior (`ct_ndt_motion_prior_weight`),
    /// which keeps the end pose from wandering; with the prior off, use 30.
    pub ct_ndt_attitude_covariance_scale: f64,
    /// The registration's covariance is multiplied by this before it is
    /// fused and published (every mode). NDT's Hessian sees the point
    /// noise, not the model, blur and sensor errors that dominate: unscaled,
    /// the NEES median was 260-1,830 on the development seeds. 100, with the
    /// filter's `q_w` 3e-5, brought the filter's NEES median to 4-12 there
    /// (`docs/design/measurement-covariance.md`).
    pub measurement_covariance_scale: f64,
    /// In `ct-ndt` mode, a frame with fewer points than this after the
    /// voxel filter is registered as one pose on the cloud motion-compensated
    /// by the filter's prediction (Eq. 12, exactly as `deblur` does, and
    /// fused as `deblur` fuses it) instead of by CT-NDT's two poses (not in
    /// the paper; 0 = always CT-NDT). Why: CT-NDT fits 12 degrees of freedom
    /// to the same points, and on a sparse frame the end pose, extrapolated
    /// from the scan's last points, wanders the most (see
    /// `docs/design/ct-ndt-motion-prior.md`). Tuned on seed 1 over 0, 3000, 4000 and
    /// 5000: slow-spin max 3.22, 2.03, 2.01, 2.95° (mean over its frames
    /// below 3000 points 0.85, 0.58, 0.55, 0.61°); tumbling max 2.27, 2.01,
    /// 1.81, 1.89° (0.94, 0.68, 0.68, 0.67°). 4000, the lowest max on both.
    /// Default 0 since the motion prior (`ct_ndt_motion_prior_weight`),
    /// which steadies sparse frames itself; with the prior off, use 4000.
    pub ct_ndt_min_points: usize,
    /// In `ct-ndt` mode (with `ct_start = "filter-prior"`), weight of a
    /// prior on the motion over the scan instead of the prior on the start
    /// pose: the filter's predicted turn and displacement, with the
    /// information of its angular and linear velocities over the scan
    /// (`(Δt² Σ_ω)⁻¹`, `(Δt² Σ_v)⁻¹`, in the start prior's units) times
    /// this. 0 = none (the start prior of the free-start CT-NDT); large = the
    /// predicted motion, i.e. `deblur`. Not in the paper; see
    /// `spacepose_registration::{RatePrior, DisplacementPrior}` and
    /// `docs/design/ct-ndt-motion-prior.md`. Default 0.4: the weight 1
    /// chosen before the filter fused a scaled covariance, brought to the
    /// same steady-state firmness (`docs/design/measurement-covariance.md`).
    pub ct_ndt_motion_prior_weight: f64,
    /// In `ct-ndt` mode, a frame whose CT-NDT stalls (stops at its
    /// iteration limit still moving by more than
    /// `loss.max_final_increment_*`) is fitted again as `deblur` fits it:
    /// one pose on the cloud motion-compensated by the prediction; that
    /// result is assessed and fused instead, and flagged
    /// ([`crate::TrackOutput::fallback`]). Not in the paper. Without it such
    /// a frame is reported `degraded` with CT-NDT's pose: tumbling seed 13,
    /// frame 84 (2,148 points), 4.50°; with it 2.69°, 3.70° since the
    /// motion prior's coarse phase (the one-pose fit stalls too, so the
    /// frame stays `degraded` and is not fused).
    /// Default true.
    pub ct_ndt_stall_fallback: bool,
    /// The start-up (not in the paper; `crate::start_up`): while the blur
    /// left by the filter's angular-rate uncertainty over a scan
    /// (`σ_ω,max · scan duration`, deg) is above this, a `deblur` frame is
    /// fitted as `ct-ndt` fits it (flagged `TrackOutput::start_up`), and in
    /// both modes the registration gets `start_up_max_iterations` and
    /// CT-NDT the last scan's rate as its guess. 0: the paper's modes from
    /// the first frame. Default [`DEFAULT_START_UP_BLUR_DEG`].
    pub start_up_blur_deg: f64,
    /// Iteration limit of the registration during the start-up (the frames
    /// above `start_up_blur_deg`, in `deblur` and `ct-ndt` modes;
    /// the larger of this and `ndt.max_iterations`). CT-NDT starts those
    /// frames from a guess up to a scan's turn off (10° at 10°/s) and took
    /// 32-50 iterations to converge on development seeds 7 and 13, where
    /// the 20 of `ndt.max_iterations` left it 4.0° and 4.3° off.
    pub start_up_max_iterations: usize,
    /// Relative-motion filter tuning.
    pub filter: FilterConfig,
    /// Degraded / lost thresholds.
    pub loss: LossConfig,
    /// The visibility gate: points behind the model at the prediction are
    /// dropped before registration (`crate::visibility`; not in the paper).
    pub visibility: VisibilityConfig,
}

/// How `ct-ndt` treats the start pose `T^s` of a scan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CtStart {
    /// Seed 000 Eq. (14): `T^s` fixed at the previous result.
    Fixed,
    /// `T^s` optimised with the end pose under a Gaussian prior: the
    /// filter's estimate at the scan start and its covariance
    /// (`spacepose_registration::register_ct_ndt_free_start`). An error in
    /// the previous result no longer bends the next scan.
    #[default]
    FilterPrior,
}

impl CtStart {
    /// The config and command-line name (`fixed`, `filter-prior`).
    pub fn as_str(self) -> &'static str {
        match self {
            CtStart::Fixed => "fixed",
            CtStart::FilterPrior => "filter-prior",
        }
    }
}

impl std::str::FromStr for CtStart {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        [CtStart::Fixed, CtStart::FilterPrior]
            .into_iter()
            .find(|c| c.as_str() == s)
            .ok_or_else(|| format!("unknown ct-ndt start {s:?} (expected fixed or filter-prior)"))
    }
}

/// Default [`TrackerConfig::release_lever_arm_m`] (m): tuned on seed 1
/// (tumbling, frames 1000-1380: ct-ndt max 7.26° without hysteresis,
/// 6.70° with 4.5 or 6 cm; deblur unchanged at 2.01°).
pub const DEFAULT_RELEASE_LEVER_ARM_M: f64 = 0.045;

/// Default [`TrackerConfig::ct_ndt_min_points`].
pub const DEFAULT_CT_NDT_MIN_POINTS: usize = 0;

/// Default [`TrackerConfig::ct_ndt_motion_prior_weight`].
pub const DEFAULT_CT_NDT_MOTION_PRIOR_WEIGHT: f64 = 0.4;

/// Default [`TrackerConfig::ct_ndt_attitude_covariance_scale`]: 1 with the
/// motion prior; 30 was tuned for the free-start CT-NDT without it.
pub const DEFAULT_CT_NDT_ATTITUDE_COVARIANCE_SCALE: f64 = 1.0;

/// Default [`TrackerConfig::measurement_covariance_scale`].
pub const DEFAULT_MEASUREMENT_COVARIANCE_SCALE: f64 = 100.0;

/// Default [`TrackerConfig::ndt_mode_min_lever_arm_m`] (m).
pub const DEFAULT_NDT_MODE_MIN_LEVER_ARM_M: f64 = 0.05;

/// Default [`TrackerConfig::icp_mode_min_lever_arm_m`] (m). Tuned on
/// slow-spin seed 1 (`icp` max: 8.64° at 5 cm, 4.74° at 5.5, 2.88° at 6;
/// at 6.5 cm the roll is held from the first frame, where the 15 m views'
/// lever arm is 5.5-6.2 cm, the filter never learns the spin, and the track
/// is lost): 5.5 cm keeps a centimetre from that cliff.
pub const DEFAULT_ICP_MODE_MIN_LEVER_ARM_M: f64 = 0.055;

/// Default `ndt.min_lever_arm_m` of the tracker (m); see
/// [`TrackerConfig::ndt`].
pub const DEFAULT_MIN_LEVER_ARM_M: f64 = 0.035;

/// Default `ndt.min_translation_cosine` of the tracker: 0, off. The hold
/// was measured on the zoo and does not pay with this filter (a 1.3 m
/// target at 15 m is lost at frame 5): `docs/design/held-translations.md`.
pub const DEFAULT_MIN_TRANSLATION_COSINE: f64 = 0.0;

/// Default of [`TrackerConfig::start_up_blur_deg`] (deg).
pub const DEFAULT_START_UP_BLUR_DEG: f64 = 1.0;

impl Default for TrackerConfig {
    fn default() -> Self {
        Self {
            mode: TrackingMode::Deblur,
            voxel_leaf_m: 0.02,
            ndt: NdtParams {
                min_lever_arm_m: DEFAULT_MIN_LEVER_ARM_M,
                min_translation_cosine: DEFAULT_MIN_TRANSLATION_COSINE,
                ..NdtParams::default()
            },
            release_lever_arm_m: DEFAULT_RELEASE_LEVER_ARM_M,
            ndt_mode_min_lever_arm_m: DEFAULT_NDT_MODE_MIN_LEVER_ARM_M,
            icp_mode_min_lever_arm_m: DEFAULT_ICP_MODE_MIN_LEVER_ARM_M,
            held_rotation: HeldRotationConfig::default(),
            icp: IcpParams::default(),
            geometric_sigma_m: 0.0,
            ct_start: CtStart::default(),
            ct_ndt_attitude_covariance_scale: DEFAULT_CT_NDT_ATTITUDE_COVARIANCE_SCALE,
            measurement_covariance_scale: DEFAULT_MEASUREMENT_COVARIANCE_SCALE,
            ct_ndt_min_points: DEFAULT_CT_NDT_MIN_POINTS,
            ct_ndt_motion_prior_weight: DEFAULT_CT_NDT_MOTION_PRIOR_WEIGHT,
            ct_ndt_stall_fallback: true,
            start_up_blur_deg: DEFAULT_START_UP_BLUR_DEG,
            start_up_max_iterations: 60,
            // The tracker checks consistency with absolute innovation limits
            // (`LossConfig`): the registration's information is far more
            // confident than the model errors justify, so a χ² gate on it
            // would reject good frames. The filter's own gate is therefore off.
            filter: FilterConfig::default(),
            loss: LossConfig::default(),
            visibility: VisibilityConfig::default(),
        }
    }
}

impl TrackerConfig {
    /// The defaults with another mode.
    pub fn with_mode(mode: TrackingMode) -> Self {
        Self {
            mode,
            ..Self::default()
        }
    }

    /// The degeneracy handling's threshold in the current mode:
    /// [`TrackerConfig::ndt_mode_min_lever_arm_m`] in `ndt` mode,
    /// [`TrackerConfig::icp_mode_min_lever_arm_m`] in `icp` mode,
    /// `ndt.min_lever_arm_m` otherwise.
    pub fn min_lever_arm_m(&self) -> f64 {
        match self.mode {
            TrackingMode::Ndt => self.ndt_mode_min_lever_arm_m,
            TrackingMode::Icp => self.icp_mode_min_lever_arm_m,
            _ => self.ndt.min_lever_arm_m,
        }
    }

    /// Checks every value; NaN fails.
    pub fn validate(&self) -> Result<(), TrackError> {
        let bad = |what: &str, v: f64| TrackError::InvalidConfig(format!("{what} = {v}"));
        if !(self.voxel_leaf_m.is_finite() && self.voxel_leaf_m > 0.0) {
            return Err(bad(
                "voxel_leaf_m must be finite and > 0",
                self.voxel_leaf_m,
            ));
        }
        for (what, s) in [
            (
                "ct_ndt_attitude_covariance_scale",
                self.ct_ndt_attitude_covariance_scale,
            ),
            (
                "measurement_covariance_scale",
                self.measurement_covariance_scale,
            ),
        ] {
            if !(s.is_finite() && s > 0.0) {
                return Err(bad(&format!("{what} must be finite and > 0"), s));
            }
        }
        let w = self.ct_ndt_motion_prior_weight;
        if !(w.is_finite() && w >= 0.0) {
            return Err(bad("ct_ndt_motion_prior_weight must be finite and >= 0", w));
        }
        let b = self.start_up_blur_deg;
        if !(b.is_finite() && b >= 0.0) {
            return Err(bad("start_up_blur_deg must be finite and >= 0", b));
        }
        let n = self.ndt_mode_min_lever_arm_m;
        if !(n.is_finite() && n >= 0.0) {
            return Err(bad("ndt_mode_min_lever_arm_m must be finite and >= 0", n));
        }
        let n = self.icp_mode_min_lever_arm_m;
        if !(n.is_finite() && n >= 0.0) {
            return Err(bad("icp_mode_min_lever_arm_m must be finite and >= 0", n));
        }
        if !(self.release_lever_arm_m.is_finite() && self.release_lever_arm_m >= 0.0) {
            return Err(bad(
                "release_lever_arm_m must be finite and >= 0",
                self.release_lever_arm_m,
            ));
        }
        if let Some((what, v)) = self.held_rotation.invalid() {
            return Err(bad(&format!("{what} out of its domain"), v));
        }
        if !(self.geometric_sigma_m.is_finite() && self.geometric_sigma_m >= 0.0) {
            return Err(bad(
                "geometric_sigma_m must be finite and >= 0",
                self.geometric_sigma_m,
            ));
        }
        self.ndt
            .validate()
            .map_err(|e| TrackError::InvalidConfig(e.to_string()))?;
        self.icp
            .validate()
            .map_err(|e| TrackError::InvalidConfig(e.to_string()))?;
        self.filter
            .validate()
            .map_err(|e| TrackError::InvalidConfig(e.to_string()))?;
        self.loss.validate()?;
        self.visibility.validate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_nan_is_not() {
        assert!(TrackerConfig::default().validate().is_ok());
        let c = TrackerConfig {
            voxel_leaf_m: f64::NAN,
            ..TrackerConfig::default()
        };
        assert!(c.validate().is_err());
        let mut c = TrackerConfig::default();
        c.loss.max_innovation_rot_deg = f64::NAN;
        assert!(c.validate().is_err());
        let mut c = TrackerConfig::default();
        c.loss.min_points = 0;
        assert!(c.validate().is_err());
        for v in [f64::NAN, -0.01, f64::INFINITY] {
            let c = TrackerConfig {
                ndt_mode_min_lever_arm_m: v,
                ..TrackerConfig::default()
            };
            assert!(c.validate().is_err(), "{v}");
            let c = TrackerConfig {
                icp_mode_min_lever_arm_m: v,
                ..TrackerConfig::default()
            };
            assert!(c.validate().is_err(), "{v}");
        }
    }

    #[test]
    fn ndt_and_icp_modes_have_their_own_hold_thresholds() {
        let ndt = TrackerConfig::with_mode(TrackingMode::Ndt);
        assert_eq!(ndt.min_lever_arm_m(), DEFAULT_NDT_MODE_MIN_LEVER_ARM_M);
        let icp = TrackerConfig::with_mode(TrackingMode::Icp);
        assert_eq!(icp.min_lever_arm_m(), DEFAULT_ICP_MODE_MIN_LEVER_ARM_M);
        for mode in [TrackingMode::Deblur, TrackingMode::CtNdt] {
            let c = TrackerConfig::with_mode(mode);
            assert_eq!(c.min_lever_arm_m(), DEFAULT_MIN_LEVER_ARM_M);
        }
        // Below the held rotation's fit threshold (see the field's doc).
        assert!(DEFAULT_NDT_MODE_MIN_LEVER_ARM_M < ndt.held_rotation.min_lever_arm_m);
    }
}
