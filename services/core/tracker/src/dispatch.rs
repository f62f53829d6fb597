//! Mode dispatch: which registration each mode runs, from which guess
//! (seed 000 Fig. 2-4), with the degeneracy handling's threshold in force.

use crate::config::{CtStart, TrackerConfig};
use crate::error::TrackError;
use crate::held_rotation::held_at;
use crate::measurement::inversion_jacobian;
use crate::mode::TrackingMode;
use crate::model::TrackingModel;
use nalgebra::{Matrix3, Matrix6, Vector6};
use spacepose_filter::{Prediction, RelativeMotionFilter};
use spacepose_geometry::{Point, Pose};
use spacepose_registration::{
    CtPriors, DisplacementPrior, NdtParams, RatePrior, Registration, ScanTimes, StartPrior,
    hold_weak_directions, register_ct_ndt, register_ct_ndt_with_priors, register_icp, register_ndt,
};

/// The last pose the tracker produced.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LastPose {
    pub(crate) t: f64,
    pub(crate) t_sensor_target: Pose,
}

/// `diag(√s I₃, I₃)`: scales the attitude block of a `[rot; trans]`
/// covariance by `s` and the cross blocks by `√s`.
pub(crate) fn attitude_scaling(s: f64) -> Matrix6<f64> {
    let r = s.sqrt();
    Matrix6::from_diagonal(&Vector6::new(r, r, r, 1.0, 1.0, 1.0))
}

/// `TrackerConfig::ct_ndt_attitude_covariance_scale` for a frame fitted as
/// `ct-ndt` fits it (`mode`, see `crate::start_up`), 1 otherwise.
pub(crate) fn ct_attitude_scale(c: &TrackerConfig, mode: TrackingMode) -> f64 {
    match mode {
        TrackingMode::CtNdt => c.ct_ndt_attitude_covariance_scale,
        _ => 1.0,
    }
}

/// The NDT parameters in force. Hysteresis of the degeneracy handling:
/// while a rotation is held (`holding`), it is released only above
/// `release_lever_arm_m`; while the hold follows a fitted rate
/// (`following_min_lever_arm_m`), only where the frame would count in the
/// fit.
pub(crate) fn ndt_params(
    c: &TrackerConfig,
    holding: bool,
    following_min_lever_arm_m: Option<f64>,
) -> NdtParams {
    let base = NdtParams {
        min_lever_arm_m: c.min_lever_arm_m(),
        ..c.ndt
    };
    if !holding || base.min_lever_arm_m <= 0.0 {
        return base;
    }
    let mut release = c.release_lever_arm_m.max(base.min_lever_arm_m);
    if let Some(fit) = following_min_lever_arm_m {
        release = release.max(fit);
    }
    NdtParams {
        min_lever_arm_m: release,
        ..base
    }
}

/// What one frame's registration needs from the tracker.
pub(crate) struct Dispatch<'a> {
    pub(crate) config: &'a TrackerConfig,
    pub(crate) model: &'a TrackingModel,
    pub(crate) filter: &'a RelativeMotionFilter,
    /// The frame's registration: the configured mode's, or `ct-ndt`'s in
    /// `deblur`'s start-up (`crate::start_up::frame_plan`).
    pub(crate) mode: TrackingMode,
    /// From [`ndt_params`].
    pub(crate) ndt: NdtParams,
    /// In the start-up (`crate::start_up`), the angular velocity (target
    /// frame, rad/s) of the last scan CT-NDT fitted, which guesses the end
    /// of this scan better than the filter's rate, still unknown.
    pub(crate) start_up_w_target: Option<nalgebra::Vector3<f64>>,
}

/// What a registration found: the pose, and for a scan CT-NDT fitted with
/// two poses, `t_target_sensor` at the scan start.
pub(crate) struct Fitted {
    pub(crate) registration: Registration,
    pub(crate) t_target_sensor_start: Option<Pose>,
}

impl From<Registration> for Fitted {
    fn from(registration: Registration) -> Self {
        Self {
            registration,
            t_target_sensor_start: None,
        }
    }
}

impl Dispatch<'_> {
    /// Runs the registration of the current mode from its initial guess;
    /// `compensated` as the frame pipeline returned it.
    pub(crate) fn register(
        &self,
        cloud: &[Point],
        compensated: bool,
        prediction: &Prediction,
        last: &LastPose,
        scan: &ScanTimes,
    ) -> Result<Fitted, TrackError> {
        let previous = last.t_sensor_target.inverse();
        let predicted = prediction.pose.inverse();
        let (map, c, ndt) = (&self.model.map, self.config, &self.ndt);
        Ok(match self.mode {
            // A held rotation is moved from the guess (the previous pose)
            // to the prediction, as in `icp` mode: where no rate has been
            // fitted it would otherwise stand still.
            TrackingMode::Ndt => {
                held_at(register_ndt(map, cloud, &previous, ndt)?, &predicted).into()
            }
            // ICP holds a rotation the surface leaves free without saying
            // so. It is held at the prediction instead, as `deblur` holds
            // it, and reported as NDT reports it, so that the hold follows
            // the fitted rate (`follow_held_rate`) when there is one. At
            // the previous pose it stood still without a fit (slow-spin
            // seed 7: from frame 1320 at 4.5 m, 1°/s, lost).
            TrackingMode::Icp => {
                let r = register_icp(self.model.icp()?, cloud, &previous, &c.icp)?;
                hold_weak_directions(map, cloud, &predicted, r, ndt).into()
            }
            TrackingMode::Deblur => register_ndt(map, cloud, &predicted, ndt)?.into(),
            // A sparse frame, compensated by the prediction: one pose.
            TrackingMode::CtNdt if compensated => register_ndt(map, cloud, &predicted, ndt)?.into(),
            TrackingMode::CtNdt => match c.ct_start {
                CtStart::Fixed => {
                    let start = self.fixed_ct_start(last, scan.start_s)?;
                    Fitted {
                        registration: register_ct_ndt(map, cloud, scan, &start, &predicted, ndt)?,
                        t_target_sensor_start: Some(start),
                    }
                }
                CtStart::FilterPrior => {
                    let priors = self.ct_priors(prediction, scan)?;
                    let guess = self
                        .start_up_guess(&priors, prediction, scan)
                        .unwrap_or(predicted);
                    let r = register_ct_ndt_with_priors(map, cloud, scan, &priors, &guess, ndt)?;
                    Fitted {
                        registration: r.end,
                        t_target_sensor_start: Some(r.t_target_sensor_start),
                    }
                }
            },
        })
    }

    /// In the start-up, the end of the scan guessed from the filter's pose
    /// at its start (the start prior's mean) turned by the last CT-NDT
    /// scan's rate (`start_up_w_target`), `R(t_s) Exp(ω Δt)`, at the
    /// predicted position (as `t_target_sensor`). `None` outside the
    /// start-up.
    fn start_up_guess(
        &self,
        priors: &CtPriors,
        at_end: &Prediction,
        scan: &ScanTimes,
    ) -> Option<Pose> {
        let w = self.start_up_w_target?;
        let start = priors.start.t_target_sensor.inverse();
        let turn = spacepose_geometry::so3::exp(&(w * (scan.end_s - scan.start_s)));
        let t_sensor_target = Pose {
            rotation: start.rotation * turn,
            translation: at_end.pose.translation,
        };
        Some(t_sensor_target.inverse())
    }

    /// `T^s` of Eq. (14): the previous result (seed 000 §3.3), carried to
    /// the scan start by the filter when scans do not abut.
    fn fixed_ct_start(&self, last: &LastPose, scan_start: f64) -> Result<Pose, TrackError> {
        Ok(
            if (scan_start - last.t).abs() < 1e-9 || scan_start < last.t {
                last.t_sensor_target.inverse()
            } else {
                self.filter.predict_at(scan_start)?.pose.inverse()
            },
        )
    }

    /// What the registration's covariance is multiplied by before the
    /// filter fuses it: the tracker's `measurement_covariance_scale` times
    /// the filter's own `registration_covariance_scale`.
    fn measurement_scale(&self) -> f64 {
        self.config.measurement_covariance_scale
            * self.filter.config().registration_covariance_scale
    }

    /// The prior on `T^s` ([`CtStart::FilterPrior`]): the filter's estimate
    /// at the scan start, its covariance carried through the inversion to
    /// `t_target_sensor`. The filter fuses the registration's covariance
    /// times `measurement_scale`, so its covariance is divided by that
    /// factor to be in the units of the registration's own information,
    /// against which the prior weighs in the optimisation.
    fn ct_start_prior(&self, scan_start: f64) -> Result<StartPrior, TrackError> {
        let at_start = self.filter.predict_at(scan_start)?;
        let a = inversion_jacobian(&at_start.pose);
        let cov = a * at_start.covariance * a.transpose();
        let cov = (cov + cov.transpose()) * 0.5;
        // Undo what the measurements were inflated by before the filter.
        let d = attitude_scaling(ct_attitude_scale(self.config, self.mode)).try_inverse();
        let scale = self.measurement_scale();
        let information = d
            .map(|d| d * cov * d)
            .and_then(|c| c.cholesky())
            .map(|c| c.inverse() * scale)
            .ok_or(TrackError::NoStartPrior { t_s: scan_start })?;
        Ok(StartPrior {
            t_target_sensor: at_start.pose.inverse(),
            information,
        })
    }

    /// The priors of the free-start CT-NDT. Without a motion prior
    /// (`TrackerConfig::ct_ndt_motion_prior_weight` = 0), the filter's
    /// estimate at the scan start. With one, the filter's predicted motion
    /// over the scan (turn and displacement) and no prior on the start pose:
    /// the filter's start pose and motion together would be a prior on the
    /// end pose, which tells the filter back what it predicted (tried: the
    /// tumble was lost). The pose is then the points', its motion over the
    /// scan the filter's within the filter's confidence.
    fn ct_priors(&self, at_end: &Prediction, scan: &ScanTimes) -> Result<CtPriors, TrackError> {
        let weight = self.config.ct_ndt_motion_prior_weight;
        if weight == 0.0 {
            return Ok(CtPriors {
                start: self.ct_start_prior(scan.start_s)?,
                rate: None,
                displacement: None,
            });
        }
        let at_start = self.filter.predict_at(scan.start_s)?;
        let dt = scan.end_s - scan.start_s;
        let scale = self.measurement_scale();
        let initial = self.filter.config();
        // Δt² times the velocity covariances, in the start prior's units.
        let information = |cov: Matrix3<f64>, initial_sigma: f64, s: f64| {
            motion_information(cov * (dt * dt), initial_sigma * dt, s)
                .map(|i| i * weight)
                .ok_or(TrackError::NoStartPrior { t_s: scan.start_s })
        };
        let cov_w = at_start
            .attitude_covariance
            .fixed_view::<3, 3>(3, 3)
            .into_owned();
        let cov_v = at_start
            .position_covariance
            .fixed_view::<3, 3>(3, 3)
            .into_owned();
        let rate = RatePrior {
            // R^e (R^s)ᵀ of t_target_sensor: Exp(-ω Δt) in the target frame.
            turn: at_end.pose.rotation.inverse() * at_start.pose.rotation,
            information: information(
                cov_w,
                initial.initial_sigma_w_degps.to_radians(),
                scale * ct_attitude_scale(self.config, self.mode),
            )?,
        };
        let displacement = DisplacementPrior {
            displacement_m: at_end.pose.translation - at_start.pose.translation,
            information: information(cov_v, initial.initial_sigma_v_mps, scale)?,
        };
        Ok(CtPriors {
            start: StartPrior {
                t_target_sensor: at_start.pose.inverse(),
                information: Matrix6::zeros(),
            },
            rate: Some(rate),
            displacement: Some(displacement),
        })
    }
}

/// The information of a motion prior (the filter's velocity covariance
/// over the scan, `cov`) in the registration's units, where only what the
/// measurements taught the filter is deflated: `I₀ + s (Σ⁻¹ − I₀)₊`, with
/// `I₀ = σ₀⁻² I` the information of the filter's initial uncertainty over
/// the scan (`initial_sigma`, the velocity's σ times Δt) and `(·)₊` the
/// positive part. The filter fused the registrations' covariance times `s`,
/// so the information they added is `s` times too small for a prior
/// weighed against the registration's own Hessian; its initial uncertainty
/// is an honest prior and stays as it is. Deflating that too (`s Σ⁻¹`)
/// made the first scan's prior ω = 0 ± 3°/s instead of ± 30°/s, which
/// pulled frame 1 of development seed 13's tumble 3.2° off
/// (`docs/design/measurement-covariance.md`). In the steady state
/// `I₀ ≪ Σ⁻¹` and this is `s Σ⁻¹`. `None` if `cov` is not positive definite.
fn motion_information(cov: Matrix3<f64>, initial_sigma: f64, s: f64) -> Option<Matrix3<f64>> {
    let cov = (cov + cov.transpose()) * 0.5;
    let info = cov.cholesky()?.inverse();
    let i0 = (initial_sigma * initial_sigma).recip();
    let learned = (info - Matrix3::identity() * i0).symmetric_eigen();
    let learned_plus = learned.eigenvectors
        * Matrix3::from_diagonal(&learned.eigenvalues.map(|e| e.max(0.0)))
        * learned.eigenvectors.transpose();
    let out = Matrix3::identity() * i0 + learned_plus * s;
    out.iter().all(|v| v.is_finite()).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::{Matrix3, attitude_scaling, motion_information};

    /// The initial uncertainty is not deflated, what was learned is, and
    /// the steady state is `s Σ⁻¹`.
    #[test]
    fn only_what_the_measurements_taught_is_deflated() {
        let s = 100.0;
        let sigma0: f64 = 0.5;
        let i0 = sigma0.powi(-2);
        // Nothing learned: the initial information as it is.
        let at_start = motion_information(Matrix3::identity() * sigma0.powi(2), sigma0, s).unwrap();
        assert!((at_start - Matrix3::identity() * i0).norm() < 1e-9 * i0);
        // Grown by process noise beyond the initial: still I₀, never less.
        let grown =
            motion_information(Matrix3::identity() * 4.0 * sigma0.powi(2), sigma0, s).unwrap();
        assert!((grown - Matrix3::identity() * i0).norm() < 1e-9 * i0);
        // Learned on one axis: that axis deflated, the others as they were.
        let cov = Matrix3::from_diagonal(&nalgebra::Vector3::new(
            0.01,
            sigma0.powi(2),
            sigma0.powi(2),
        ));
        let m = motion_information(cov, sigma0, s).unwrap();
        assert!((m[(0, 0)] - (i0 + s * (100.0 - i0))).abs() < 1e-6);
        assert!((m[(1, 1)] - i0).abs() < 1e-9 && m[(0, 1)].abs() < 1e-9);
        // Steady state: within 1 % of s Σ⁻¹.
        let steady = motion_information(Matrix3::identity() * 1e-6, sigma0, s).unwrap();
        assert!((steady[(2, 2)] / (s * 1e6) - 1.0).abs() < 0.01);
        assert!(motion_information(Matrix3::zeros(), sigma0, s).is_none());
    }
    use nalgebra::Matrix6;

    /// `D C D` multiplies the attitude block by `s`, the cross blocks by
    /// `√s`, and leaves the position block alone.
    #[test]
    fn attitude_scaling_scales_the_blocks() {
        let c = Matrix6::from_fn(|i, j| 1.0 + (i + j) as f64 + if i == j { 10.0 } else { 0.0 });
        let d = attitude_scaling(30.0);
        let scaled = d * c * d;
        for i in 0..6 {
            for j in 0..6 {
                let f = match (i < 3, j < 3) {
                    (true, true) => 30.0,
                    (false, false) => 1.0,
                    _ => 30f64.sqrt(),
                };
                assert!((scaled[(i, j)] - f * c[(i, j)]).abs() < 1e-9, "({i}, {j})");
            }
        }
        assert_eq!(attitude_scaling(1.0), Matrix6::identity());
    }
}
