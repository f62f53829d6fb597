//! The tracking loop (seed 000 Fig. 2-4).

use crate::config::{CtStart, TrackerConfig};
use crate::error::TrackError;
use crate::held_rotation::{HeldRotation, turn_about};
use crate::measurement::{covariance_sensor_target, inversion_jacobian, measurement_information};
use crate::mode::TrackingMode;
use crate::model::TrackingModel;
use crate::output::{Timings, TrackOutput};
use crate::status::TrackStatus;
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};
use spacepose_filter::{MotionCompensation, Prediction, RelativeMotionFilter};
use spacepose_geometry::{Point, Pose, VoxelFilter, so3};
use spacepose_registration::{
    CtPriors, DisplacementPrior, NdtParams, RatePrior, Registration, ScanTimes, StartPrior,
    hold_weak_rotations, register_ct_ndt, register_ct_ndt_with_priors, register_icp, register_ndt,
};
use std::time::Instant;

/// `diag(√s I₃, I₃)`: scales the attitude block of a `[rot; trans]`
/// covariance by `s` and the cross blocks by `√s`.
fn attitude_scaling(s: f64) -> Matrix6<f64> {
    let r = s.sqrt();
    Matrix6::from_diagonal(&Vector6::new(r, r, r, 1.0, 1.0, 1.0))
}

/// The last pose the tracker produced.
#[derive(Debug, Clone, Copy)]
struct LastPose {
    t: f64,
    t_sensor_target: Pose,
}

/// A frame's registration and how it was obtained ([`Tracker::measure`]).
struct Measured {
    registration: Registration,
    /// The cloud was motion-compensated by the prediction (Eq. 12).
    compensated: bool,
    /// Points the registration saw.
    points_used: usize,
    /// Fitted by the stall fallback.
    fallback: bool,
    preprocess_ms: f64,
    /// Registration, the fallback included.
    registration_ms: f64,
}

/// Why a frame carried no measurement, and what is known of it.
struct Missing {
    reason: String,
    /// Points left after pre-processing (0 when it failed or was not the
    /// cause).
    points_used: usize,
    /// 0 when pre-processing was not the cause.
    preprocess_ms: f64,
}

impl Missing {
    /// No measurement for `reason`, pre-processing aside.
    fn because(reason: String) -> Self {
        Self {
            reason,
            points_used: 0,
            preprocess_ms: 0.0,
        }
    }
}

/// Follows the target frame after frame. Not thread-safe by design: one
/// tracker per stream of frames.
pub struct Tracker {
    config: TrackerConfig,
    model: TrackingModel,
    filter: RelativeMotionFilter,
    voxel: VoxelFilter,
    last: Option<LastPose>,
    lost: bool,
    consecutive_degraded: u32,
    /// The last registration held a rotation at the prediction (see
    /// `TrackerConfig::release_lever_arm_m`).
    holding: bool,
    /// The track's recent poses and the rate a held rotation follows.
    held: HeldRotation,
}

impl Tracker {
    /// A tracker for `model`, not yet initialised.
    pub fn new(config: TrackerConfig, model: TrackingModel) -> Result<Self, TrackError> {
        config.validate()?;
        let filter = RelativeMotionFilter::new(config.filter.clone())?;
        let voxel = VoxelFilter::new(config.voxel_leaf_m)?;
        let held = HeldRotation::new(config.held_rotation.clone());
        if config.mode == TrackingMode::Icp {
            // Only this mode needs it (crate::model): build it before the first frame.
            model.icp()?;
        }
        Ok(Self {
            config,
            model,
            filter,
            voxel,
            last: None,
            lost: false,
            consecutive_degraded: 0,
            holding: false,
            held,
        })
    }

    /// The configuration in force.
    pub fn config(&self) -> &TrackerConfig {
        &self.config
    }

    /// The current mode.
    pub fn mode(&self) -> TrackingMode {
        self.config.mode
    }

    /// Changes the mode between two frames; the filter state is kept.
    /// Switching to `icp` builds the ICP model now if it was not yet
    /// (~1 s for deos); if that fails, the mode is left unchanged.
    pub fn set_mode(&mut self, mode: TrackingMode) -> Result<(), TrackError> {
        if mode == TrackingMode::Icp {
            self.model.icp()?;
        }
        self.config.mode = mode;
        Ok(())
    }

    /// True once initialised and not lost.
    pub fn is_tracking(&self) -> bool {
        self.last.is_some() && !self.lost
    }

    /// The filter prediction at `t` (for seeding other estimators).
    pub fn predict_at(&self, t: f64) -> Result<Prediction, TrackError> {
        Ok(self.filter.predict_at(t)?)
    }

    /// Replaces the local filter with the authoritative state published by
    /// the filter service (suite deployments). Ignored while the track is
    /// not initialised or when the state is older than the local one.
    pub fn restore_filter(&mut self, state: &Prediction) -> Result<(), TrackError> {
        if self.last.is_none() || self.filter.time().is_some_and(|t| state.t < t) {
            return Ok(());
        }
        self.filter.restore(state)?;
        Ok(())
    }

    /// (Re)starts tracking from `t_sensor_target` at time `t` (truth before
    /// acquisition exists, an acquisition result afterwards). Unknown rates
    /// are passed as zeros: the filter starts at ω = 0 (seed 000 §5.2).
    pub fn initialize(
        &mut self,
        t: f64,
        t_sensor_target: &Pose,
        v_sensor: Vector3<f64>,
        w_target: Vector3<f64>,
    ) -> Result<(), TrackError> {
        self.filter
            .initialize(t, t_sensor_target, v_sensor, w_target)?;
        self.last = Some(LastPose {
            t,
            t_sensor_target: *t_sensor_target,
        });
        self.lost = false;
        self.consecutive_degraded = 0;
        self.holding = false;
        self.held.reset();
        Ok(())
    }

    /// Processes one frame: `points` in the sensor frame with per-point
    /// timestamps in `[scan_start, scan_end]`.
    ///
    /// Per-frame failures (empty or all-NaN cloud, no correspondence,
    /// degenerate geometry, inconsistency) are *reported* in the output's
    /// status; `Err` is reserved for misuse (not initialised, scan times
    /// not finite or not increasing).
    ///
    /// A cloud with fewer than `loss.min_points` points after pre-processing
    /// (empty included) is no measurement: the target is not in view. It is
    /// `lost` at once (the degraded-frames rule is for doubtful
    /// measurements; here there is nothing to track), its pose is the filter
    /// prediction at the scan end, [`TrackOutput::has_measurement`] is
    /// false, and nothing is fed to the filter.
    pub fn process(
        &mut self,
        points: &[Point],
        scan_start: f64,
        scan_end: f64,
    ) -> Result<TrackOutput, TrackError> {
        let started = Instant::now();
        let last = self.last.ok_or(TrackError::NotInitialized)?;
        check_scan_times(scan_start, scan_end, last.t)?;
        let prediction = self.filter.predict_at(scan_end)?;
        if self.lost {
            return Ok(self.lost_output(
                &prediction,
                points.len(),
                "track lost: awaiting re-initialisation",
                started,
            ));
        }
        let scan = ScanTimes {
            start_s: scan_start,
            end_s: scan_end,
        };
        let m = match self.measure(points, &prediction, &last, &scan) {
            Ok(m) => m,
            Err(missing) => {
                let mut out = self.declare_lost(&prediction, points.len(), missing.reason, started);
                (out.points_used, out.timings.preprocess_ms) =
                    (missing.points_used, missing.preprocess_ms);
                return Ok(out);
            }
        };
        self.holding = m.registration.degenerate_directions > 0;
        let registration = self.follow_held_rate(scan_end, m.registration);
        let counts = (points.len(), m.points_used);
        let mut out = self.assess(registration, m.compensated, &prediction, scan_end, counts)?;
        out.fallback = m.fallback;
        self.record_tracked(&out);
        out.timings = Timings {
            preprocess_ms: m.preprocess_ms,
            registration_ms: m.registration_ms,
            total_ms: ms(started),
        };
        Ok(out)
    }

    /// Pre-processing and registration of one frame (with the stall
    /// fallback), or why there is no measurement: pre-processing failed, too
    /// few points are left (`loss.min_points`: the target is not in view),
    /// or the registration failed.
    fn measure(
        &mut self,
        points: &[Point],
        prediction: &Prediction,
        last: &LastPose,
        scan: &ScanTimes,
    ) -> Result<Measured, Missing> {
        let pre = Instant::now();
        let (cloud, compensated) = self
            .preprocess(points, prediction)
            .map_err(|e| Missing::because(e.to_string()))?;
        let preprocess_ms = ms(pre);
        if cloud.len() < self.config.loss.min_points {
            let reason = format!(
                "no measurement: {} points after pre-processing, fewer than loss.min_points = {} \
                 (target not in view)",
                cloud.len(),
                self.config.loss.min_points
            );
            let points_used = cloud.len();
            return Err(Missing {
                reason,
                points_used,
                preprocess_ms,
            });
        }
        let reg_start = Instant::now();
        let registration = self
            .register(&cloud, compensated, prediction, last, scan)
            .map_err(|e| Missing::because(e.to_string()))?;
        let fallback =
            self.stall_fallback(points, &registration, compensated, prediction, last, scan);
        let (registration, compensated, points_used, fallback) = match fallback {
            Some((r, n)) => (r, true, n, true),
            None => (registration, compensated, cloud.len(), false),
        };
        Ok(Measured {
            registration,
            compensated,
            points_used,
            fallback,
            preprocess_ms,
            registration_ms: ms(reg_start),
        })
    }

    /// A frame reported `tracking` adds its pose to the history the held
    /// rotation's rate is fitted on.
    fn record_tracked(&mut self, out: &TrackOutput) {
        if let (TrackStatus::Tracking, Some(r)) = (out.status, out.registration.as_ref()) {
            self.held.record(
                out.t,
                &r.t_target_sensor,
                r.weakest_lever_arm_m,
                self.holding,
            );
        }
    }

    /// A result that held one rotation is turned about it to follow the
    /// rate fitted before the hold (see [`crate::held_rotation`]).
    fn follow_held_rate(&mut self, t: f64, mut registration: Registration) -> Registration {
        if registration.degenerate_directions != 1 {
            return registration;
        }
        let Some(h) = registration.geometric_information else {
            return registration;
        };
        if let Some(axis) = weakest_rotation(&h)
            && let Some(c) = self
                .held
                .correct(t, &mut registration.t_target_sensor, &axis, &h)
        {
            tracing::debug!(
                t,
                rate_deg_s = c.rate_rad_s.to_degrees(),
                turn_deg = c.turn_rad.to_degrees(),
                "held rotation follows the fitted rate"
            );
        }
        registration
    }

    /// [`TrackerConfig::ct_ndt_stall_fallback`]: when CT-NDT stalled, the
    /// one-pose fit of the cloud compensated by the prediction (`deblur`'s
    /// registration) and its point count; `None` otherwise, or when that
    /// fit fails too (the stalled result then stands, and is doubted).
    fn stall_fallback(
        &mut self,
        points: &[Point],
        registration: &Registration,
        compensated: bool,
        prediction: &Prediction,
        last: &LastPose,
        scan: &ScanTimes,
    ) -> Option<(Registration, usize)> {
        let c = &self.config;
        if c.mode != TrackingMode::CtNdt
            || compensated
            || !c.ct_ndt_stall_fallback
            || !self.stalled(registration)
        {
            return None;
        }
        let cloud = self.compensated_cloud(points, prediction).ok()?;
        match self.register(&cloud, true, prediction, last, scan) {
            Ok(r) => {
                tracing::debug!(
                    t = scan.end_s,
                    iterations = registration.iterations,
                    "CT-NDT stalled: the frame is fitted as one pose on the compensated cloud"
                );
                Some((r, cloud.len()))
            }
            Err(e) => {
                tracing::debug!(t = scan.end_s, error = %e, "CT-NDT stalled, and so did its fallback");
                None
            }
        }
    }

    /// Motion compensation (Eq. 12) and the voxel filter. Returns the cloud
    /// and whether it was compensated: always in `deblur` mode, and in
    /// `ct-ndt` mode when the frame has fewer than
    /// `TrackerConfig::ct_ndt_min_points` points after the voxel filter
    /// (then one pose is fitted, see [`TrackerConfig::ct_ndt_min_points`]).
    /// The raw points are compensated before the voxel filter: the
    /// scanner's rosette revisits a voxel at different times, so a voxel's
    /// mean timestamp does not compensate its mean point.
    fn preprocess(
        &mut self,
        points: &[Point],
        prediction: &Prediction,
    ) -> Result<(Vec<Point>, bool), TrackError> {
        match self.config.mode {
            TrackingMode::Deblur => {}
            TrackingMode::CtNdt => {
                let cloud = self.voxel.filter(points)?.points;
                if cloud.len() >= self.config.ct_ndt_min_points {
                    return Ok((cloud, false));
                }
            }
            TrackingMode::Ndt | TrackingMode::Icp => {
                return Ok((self.voxel.filter(points)?.points, false));
            }
        }
        Ok((self.compensated_cloud(points, prediction)?, true))
    }

    /// The raw points motion-compensated to the scan end by the prediction
    /// (Eq. 12), then voxel-filtered.
    fn compensated_cloud(
        &mut self,
        points: &[Point],
        prediction: &Prediction,
    ) -> Result<Vec<Point>, TrackError> {
        // One copy of the finite points, compensated in place (Eq. 12, one
        // sin_cos per point about the fixed axis R ω).
        let mut finite: Vec<Point> = points.iter().copied().filter(Point::is_finite).collect();
        MotionCompensation::from_prediction(prediction)?.compensate_in_place(&mut finite)?;
        Ok(self.voxel.filter(&finite)?.points)
    }

    /// Runs the registration of the current mode from its initial guess;
    /// `compensated` as [`Tracker::preprocess`] returned it.
    fn register(
        &self,
        cloud: &[Point],
        compensated: bool,
        prediction: &Prediction,
        last: &LastPose,
        scan: &ScanTimes,
    ) -> Result<Registration, TrackError> {
        let previous = last.t_sensor_target.inverse();
        let predicted = prediction.pose.inverse();
        let (map, c) = (&self.model.map, &self.config);
        // Hysteresis of the degeneracy handling: while a rotation is held,
        // it is released only above `release_lever_arm_m`; while the hold
        // follows a fitted rate, only where the frame would count in the fit.
        let base = NdtParams {
            min_lever_arm_m: c.min_lever_arm_m(),
            ..c.ndt
        };
        let mut release = c.release_lever_arm_m.max(base.min_lever_arm_m);
        if self.held.following() {
            release = release.max(self.held.min_lever_arm_m());
        }
        let held = NdtParams {
            min_lever_arm_m: release,
            ..base
        };
        let ndt = if self.holding && base.min_lever_arm_m > 0.0 {
            &held
        } else {
            &base
        };
        Ok(match c.mode {
            // A held rotation is moved from the guess (the previous pose)
            // to the prediction, as in `icp` mode: where no rate has been
            // fitted it would otherwise stand still.
            TrackingMode::Ndt => held_at(register_ndt(map, cloud, &previous, ndt)?, &predicted),
            // ICP holds a rotation the surface leaves free without saying
            // so. It is held at the prediction instead, as `deblur` holds
            // it, and reported as NDT reports it, so that the hold follows
            // the fitted rate (`follow_held_rate`) when there is one. At
            // the previous pose it stood still without a fit (slow-spin
            // seed 7: from frame 1320 at 4.5 m, 1°/s, lost).
            TrackingMode::Icp => {
                let r = register_icp(self.model.icp()?, cloud, &previous, &c.icp)?;
                hold_weak_rotations(map, cloud, &predicted, r, ndt)
            }
            TrackingMode::Deblur => register_ndt(map, cloud, &predicted, ndt)?,
            // A sparse frame, compensated by the prediction: one pose.
            TrackingMode::CtNdt if compensated => register_ndt(map, cloud, &predicted, ndt)?,
            TrackingMode::CtNdt => match c.ct_start {
                CtStart::Fixed => {
                    let start = self.fixed_ct_start(last, scan.start_s)?;
                    register_ct_ndt(map, cloud, scan, &start, &predicted, ndt)?
                }
                CtStart::FilterPrior => {
                    let priors = self.ct_priors(prediction, scan)?;
                    register_ct_ndt_with_priors(map, cloud, scan, &priors, &predicted, ndt)?.end
                }
            },
        })
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

    /// The prior on `T^s` ([`CtStart::FilterPrior`]): the filter's estimate
    /// at the scan start, its covariance carried through the inversion to
    /// `t_target_sensor`. The filter fuses the registration's covariance
    /// times `filter.registration_covariance_scale`, so its covariance is
    /// divided by that factor to be in the units of the registration's own
    /// information, against which the prior weighs in the optimisation.
    fn ct_start_prior(&self, scan_start: f64) -> Result<StartPrior, TrackError> {
        let at_start = self.filter.predict_at(scan_start)?;
        let a = inversion_jacobian(&at_start.pose);
        let cov = a * at_start.covariance * a.transpose();
        let cov = (cov + cov.transpose()) * 0.5;
        // Undo what the measurements were inflated by before the filter.
        let d = attitude_scaling(self.ct_attitude_scale()).try_inverse();
        let scale = self.filter.config().registration_covariance_scale;
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
        let scale = self.filter.config().registration_covariance_scale * weight;
        // Δt² times the velocity covariances, in the start prior's units.
        let information = |cov: Matrix3<f64>, s: f64| {
            let cov = cov * (dt * dt);
            ((cov + cov.transpose()) * 0.5)
                .cholesky()
                .map(|c| c.inverse() * s)
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
            information: information(cov_w, scale * self.ct_attitude_scale())?,
        };
        let displacement = DisplacementPrior {
            displacement_m: at_end.pose.translation - at_start.pose.translation,
            information: information(cov_v, scale)?,
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

    /// `TrackerConfig::ct_ndt_attitude_covariance_scale` in `ct-ndt` mode,
    /// 1 otherwise.
    fn ct_attitude_scale(&self) -> f64 {
        match self.config.mode {
            TrackingMode::CtNdt => self.config.ct_ndt_attitude_covariance_scale,
            _ => 1.0,
        }
    }

    /// The measurement covariance `[rot; trans]` with its attitude inflated
    /// by [`Tracker::ct_attitude_scale`] (`D C D`, `D = diag(√s I, I)`),
    /// unless the cloud was `compensated`: a sparse `ct-ndt` frame fitted
    /// as one pose is fused as `deblur` fuses it, since the inflation is for
    /// CT-NDT's extrapolated end pose (with it, the filter lost seed 1's
    /// tumble in a sparse stretch, its rate hardly corrected).
    fn attitude_scaled(&self, c: Matrix6<f64>, compensated: bool) -> Matrix6<f64> {
        if compensated {
            return c;
        }
        let d = attitude_scaling(self.ct_attitude_scale());
        d * c * d
    }

    /// Quality and consistency checks, filter update, status.
    /// `(points_in, points_used)` are the frame's point counts before and
    /// after pre-processing.
    fn assess(
        &mut self,
        registration: Registration,
        compensated: bool,
        prediction: &Prediction,
        t: f64,
        (points_in, points_used): (usize, usize),
    ) -> Result<TrackOutput, TrackError> {
        let measured = registration.t_sensor_target();
        let innovation_rot_deg =
            so3::distance(&measured.rotation, &prediction.pose.rotation).to_degrees();
        let innovation_pos_m = (measured.translation - prediction.pose.translation).norm();
        let information = measurement_information(&registration, self.config.geometric_sigma_m);
        let covariance = covariance_sensor_target(&registration.t_target_sensor, &information)
            .map(|c| self.attitude_scaled(c, compensated));
        let mut reasons = self.quality_issues(&registration);
        reasons.extend(self.inconsistency(innovation_rot_deg, innovation_pos_m));
        if reasons.is_empty() {
            let outcome = self.filter.update(t, &measured, covariance)?;
            if !outcome.fused {
                reasons.push(format!(
                    "filter gate: Mahalanobis² {:.1}",
                    outcome.mahalanobis2
                ));
            }
        }
        let status = self.status_after(&mut reasons);
        let (t_sensor_target, covariance) =
            self.published(status, measured, covariance, prediction);
        self.last = Some(LastPose { t, t_sensor_target });
        let estimate = self.filter.predict_at(t)?;
        Ok(TrackOutput {
            t,
            t_sensor_target,
            covariance,
            status,
            reason: reasons.join("; "),
            registration: Some(registration),
            innovation_rot_deg,
            innovation_pos_m,
            w_target: estimate.w_target,
            v_sensor: estimate.v_sensor,
            points_in,
            points_used,
            timings: Timings::default(),
            fallback: false,
        })
    }

    /// The reason to doubt a measurement that jumps from the prediction by
    /// more than `loss.max_innovation_*`.
    fn inconsistency(&self, innovation_rot_deg: f64, innovation_pos_m: f64) -> Option<String> {
        let l = &self.config.loss;
        (innovation_rot_deg > l.max_innovation_rot_deg
            || innovation_pos_m > l.max_innovation_pos_m)
            .then(|| {
                format!(
                    "inconsistent with prediction ({innovation_rot_deg:.1} deg, {innovation_pos_m:.3} m)"
                )
            })
    }

    /// The status after a frame doubted for `reasons` (none: `tracking`):
    /// `degraded`, or `lost` once `loss.max_consecutive_degraded` frames in
    /// a row were doubted (that reason is then added).
    fn status_after(&mut self, reasons: &mut Vec<String>) -> TrackStatus {
        if reasons.is_empty() {
            self.consecutive_degraded = 0;
            return TrackStatus::Tracking;
        }
        self.consecutive_degraded += 1;
        if self.consecutive_degraded < self.config.loss.max_consecutive_degraded {
            return TrackStatus::Degraded;
        }
        self.lost = true;
        reasons.push(format!(
            "{} degraded frames in a row",
            self.consecutive_degraded
        ));
        TrackStatus::Lost
    }

    /// The pose (and its covariance) the tracker publishes for a frame: the
    /// measurement, unless it was doubted (not fused) in a mode whose
    /// estimator is the filter (`deblur`, `ct-ndt`: its prediction seeds
    /// every frame). There the filter's prediction stands, as it does for a
    /// frame without a measurement: a rejected measurement is not the
    /// estimate (tumbling seed 13, frame 84: a stalled fit 3.70° off, the
    /// prediction 0.58°). In `ndt` and `icp` modes (Fig. 2) the registration
    /// is the estimate and the next guess, so a doubted one is published as
    /// it is, flagged by the status.
    fn published(
        &self,
        status: TrackStatus,
        measured: Pose,
        covariance: Option<Matrix6<f64>>,
        prediction: &Prediction,
    ) -> (Pose, Option<Matrix6<f64>>) {
        if status == TrackStatus::Tracking || !self.config.mode.uses_prediction() {
            (measured, covariance)
        } else {
            (prediction.pose, Some(prediction.covariance))
        }
    }

    /// A registration that stopped at its iteration limit while still
    /// moving by more than `loss.max_final_increment_*`.
    fn stalled(&self, r: &Registration) -> bool {
        let l = &self.config.loss;
        !r.converged
            && (r.last_increment.rotation_rad.to_degrees() > l.max_final_increment_deg
                || r.last_increment.translation_m > l.max_final_increment_m)
    }

    /// Reasons to doubt a registration on its own figures.
    fn quality_issues(&self, r: &Registration) -> Vec<String> {
        let l = &self.config.loss;
        let mut reasons = Vec::new();
        if r.inliers < l.min_inliers || r.inlier_fraction() < l.min_inlier_fraction {
            reasons.push(format!(
                "{} inliers ({:.0}%)",
                r.inliers,
                100.0 * r.inlier_fraction()
            ));
        }
        let max_cost = if self.config.mode == TrackingMode::Icp {
            l.max_mean_cost_icp_m2
        } else {
            l.max_mean_cost_ndt
        };
        if r.cost.mean.is_nan() || r.cost.mean > max_cost {
            reasons.push(format!(
                "mean cost {:.3e} above {max_cost:.3e}",
                r.cost.mean
            ));
        }
        if self.stalled(r) {
            reasons.push(format!(
                "no convergence after {} iterations (last step {:.2} deg, {:.3} m)",
                r.iterations,
                r.last_increment.rotation_rad.to_degrees(),
                r.last_increment.translation_m
            ));
        }
        reasons
    }

    fn declare_lost(
        &mut self,
        prediction: &Prediction,
        points_in: usize,
        reason: String,
        started: Instant,
    ) -> TrackOutput {
        self.lost = true;
        self.lost_output(prediction, points_in, &reason, started)
    }

    fn lost_output(
        &self,
        prediction: &Prediction,
        points_in: usize,
        reason: &str,
        started: Instant,
    ) -> TrackOutput {
        TrackOutput {
            t: prediction.t,
            t_sensor_target: prediction.pose,
            covariance: None,
            status: TrackStatus::Lost,
            reason: reason.to_string(),
            registration: None,
            innovation_rot_deg: f64::NAN,
            innovation_pos_m: f64::NAN,
            w_target: prediction.w_target,
            v_sensor: prediction.v_sensor,
            points_in,
            points_used: 0,
            timings: Timings {
                total_ms: ms(started),
                ..Timings::default()
            },
            fallback: false,
        }
    }
}

/// The rotation axis (target frame) the geometric information `h`
/// (`δ = [rot; trans]`) constrains least once the translation is
/// marginalised out (the held one, as the registration's degeneracy
/// handling finds it); `None` when `h` is not usable.
fn weakest_rotation(h: &Matrix6<f64>) -> Option<Vector3<f64>> {
    let h_rr = h.fixed_view::<3, 3>(0, 0).into_owned();
    let h_rt = h.fixed_view::<3, 3>(0, 3).into_owned();
    let h_tt_inv = h.fixed_view::<3, 3>(3, 3).into_owned().try_inverse()?;
    let schur = h_rr - h_rt * h_tt_inv * h_rt.transpose();
    let eig = ((schur + schur.transpose()) * 0.5).symmetric_eigen();
    let i = eig.eigenvalues.imin();
    let v = eig.eigenvectors.column(i).into_owned();
    v.iter().all(|x| x.is_finite()).then_some(v)
}

/// `registration` with its held rotation (one, as [`weakest_rotation`]
/// finds it) turned to that of `reference`, with the translation that goes
/// with the turn; unchanged when it held none.
fn held_at(mut registration: Registration, reference: &Pose) -> Registration {
    if registration.degenerate_directions != 1 {
        return registration;
    }
    let Some(h) = registration.geometric_information else {
        return registration;
    };
    if let Some(axis) = weakest_rotation(&h) {
        let eps = reference.ominus(&registration.t_target_sensor);
        let turn = axis.dot(&eps.fixed_rows::<3>(0));
        registration.t_target_sensor = turn_about(&registration.t_target_sensor, &axis, turn, &h);
    }
    registration
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}

/// Rejects non-finite or reversed scan times, and a scan that does not end
/// after the previous one (`previous_end_s`).
fn check_scan_times(start_s: f64, end_s: f64, previous_end_s: f64) -> Result<(), TrackError> {
    if start_s.is_finite() && end_s.is_finite() && start_s <= end_s && end_s > previous_end_s {
        Ok(())
    } else {
        Err(TrackError::InvalidScanTimes {
            start_s,
            end_s,
            previous_end_s: Some(previous_end_s),
        })
    }
}

#[cfg(test)]
mod helper_tests {
    use super::{attitude_scaling, held_at, weakest_rotation};
    use nalgebra::{Matrix6, Vector3, Vector6};
    use spacepose_geometry::Pose;
    use spacepose_registration::{Cost, Increment, Registration};

    /// A result at the identity that held `held` rotations, with geometric
    /// information `h`.
    fn held_result(held: usize, h: Matrix6<f64>) -> Registration {
        Registration {
            t_target_sensor: Pose::identity(),
            converged: true,
            iterations: 3,
            cost: Cost {
                total: 1.0,
                mean: 0.01,
            },
            inliers: 100,
            valid_points: 100,
            skipped_non_finite: 0,
            mean_squared_distance_m2: 1e-4,
            f_conv_m2: None,
            information: Matrix6::identity() * 7.0,
            last_increment: Increment::default(),
            degenerate_directions: held,
            weakest_lever_arm_m: 0.01,
            geometric_information: Some(h),
        }
    }

    /// The held rotation (about x here) takes the reference's angle; the
    /// measured ones stay the registration's.
    #[test]
    fn a_held_rotation_is_turned_to_the_reference() {
        let mut h = Matrix6::identity() * 100.0;
        h[(0, 0)] = 1e-4;
        let reference = Pose::identity().oplus(&Vector6::new(
            3f64.to_radians(),
            1f64.to_radians(),
            0.0,
            0.0,
            0.0,
            0.02,
        ));
        let moved = held_at(held_result(1, h), &reference);
        let eps = moved.t_target_sensor.ominus(&Pose::identity());
        assert!((eps[0].to_degrees() - 3.0).abs() < 1e-6, "{eps:?}");
        assert!(eps[1].abs() < 1e-9 && eps[5].abs() < 1e-9, "{eps:?}");
        // Nothing held: unchanged.
        let kept = held_at(held_result(0, h), &reference);
        assert_eq!(kept.t_target_sensor, Pose::identity());
    }

    /// The held axis is the rotation with the least information once the
    /// translation is marginalised out, even when the raw rotation block
    /// alone would point elsewhere.
    #[test]
    fn weakest_rotation_marginalises_the_translation() {
        let mut h = Matrix6::identity() * 100.0;
        h[(0, 0)] = 1.0; // about x: weak
        let axis = weakest_rotation(&h).expect("an axis");
        assert!((axis.abs() - Vector3::x()).norm() < 1e-9, "{axis}");
        // Rotation about y strongly coupled to translation along z: its
        // Schur complement 100 − 99.9²/100 ≈ 0.2 is the weakest.
        let mut h = Matrix6::identity() * 100.0;
        h[(0, 0)] = 50.0;
        h[(1, 5)] = 99.9;
        h[(5, 1)] = 99.9;
        let axis = weakest_rotation(&h).expect("an axis");
        assert!((axis.abs() - Vector3::y()).norm() < 1e-9, "{axis}");
        // A singular translation block gives no axis.
        let mut h = Matrix6::identity();
        h[(4, 4)] = 0.0;
        assert!(weakest_rotation(&h).is_none());
    }

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
