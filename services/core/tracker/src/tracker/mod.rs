//! The tracking loop (seed 000 Fig. 2-4): the frame path
//! ([`crate::pipeline`]), the mode's registration ([`crate::dispatch`]),
//! the held rotation ([`crate::held_rotation`]), the assessment
//! ([`crate::assess`]) and the filter, frame after frame.

use crate::assess::{
    attitude_scaled, held_doubt, inconsistency, published, quality_issues, rigid_lag_doubt,
};
use crate::config::TrackerConfig;
use crate::dispatch::{Dispatch, LastPose, ndt_params};
use crate::error::TrackError;
use crate::held_axes::HeldAxes;
use crate::held_rotation::HeldRotation;
use crate::innovation::InnovationHistory;
use crate::measurement::{covariance_sensor_target, measurement_information};
use crate::mode::TrackingMode;
use crate::model::TrackingModel;
use crate::output::{Timings, TrackOutput};
use crate::pipeline::FramePipeline;
use crate::status::TrackStatus;
use nalgebra::Vector3;
use spacepose_filter::{Prediction, RelativeMotionFilter};
use spacepose_geometry::{Point, Pose, so3};
use spacepose_registration::{Registration, ScanTimes};
use std::time::Instant;

mod measure;
mod scan;

use scan::{check_scan_times, ms, scan_rate};

/// Follows the target frame after frame. Not thread-safe by design: one
/// tracker per stream of frames.
pub struct Tracker {
    config: TrackerConfig,
    model: TrackingModel,
    filter: RelativeMotionFilter,
    pipeline: FramePipeline,
    last: Option<LastPose>,
    lost: bool,
    consecutive_degraded: u32,
    /// The last registration held a rotation at the prediction (see
    /// `TrackerConfig::release_lever_arm_m`).
    holding: bool,
    /// The track's recent poses and the rate a held rotation follows.
    held: HeldRotation,
    /// The angular velocity (target frame, rad/s) over the last scan that
    /// CT-NDT fitted with two poses and was tracked; reset at each
    /// (re)initialisation (`crate::start_up`).
    scan_w_target: Option<Vector3<f64>>,
    /// The recent attitude innovations the limit follows
    /// (`crate::innovation`); reset at each (re)initialisation.
    innovations: InnovationHistory,
    /// The filter holds only an initialisation (an acquisition, a command,
    /// the truth): no registration has reached it since. The next one
    /// restarts it instead of updating it (see [`Tracker::initialize`]).
    seeded: bool,
}

impl Tracker {
    /// A tracker for `model`, not yet initialised.
    pub fn new(config: TrackerConfig, model: TrackingModel) -> Result<Self, TrackError> {
        config.validate()?;
        let mut config = config;
        config.loss = config.loss.resolved(&model.thresholds);
        let filter = RelativeMotionFilter::new(config.filter.clone())?;
        let pipeline = FramePipeline::new(config.voxel_leaf_m)?;
        let held = HeldRotation::new(config.held_rotation.clone());
        if config.mode == TrackingMode::Icp {
            // Only this mode needs it (crate::model): build it before the first frame.
            model.icp()?;
        }
        Ok(Self {
            config,
            model,
            filter,
            pipeline,
            last: None,
            lost: false,
            consecutive_degraded: 0,
            holding: false,
            held,
            scan_w_target: None,
            innovations: InnovationHistory::default(),
            seeded: false,
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
        // A state newer than the local filter's fused a registration there.
        let newer = self.filter.time().is_some_and(|t| state.t > t);
        self.filter.restore(state)?;
        self.seeded &= !newer;
        Ok(())
    }

    /// (Re)starts tracking from `t_sensor_target` at time `t` (truth before
    /// acquisition exists, an acquisition result afterwards). Unknown rates
    /// are passed as zeros: the filter starts at ω = 0 (seed 000 §5.2).
    ///
    /// The pose is a seed, not a measurement of the motion: the first
    /// registration the checks accept restarts the filter at its own pose
    /// (ω = 0, the initial uncertainty) instead of updating it, so the
    /// rate is learned from registrations only. An acquisition may be up
    /// to 10° off and still be correct; fused, its error becomes a rate
    /// the filter then believes (docs/design/acquisition-seed.md).
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
        self.scan_w_target = None;
        self.innovations.reset();
        self.seeded = true;
        Ok(())
    }

    /// [`Self::initialize`] at a pose the tracker registered itself (the
    /// acquisition's own frame, refined): the filter's next registration
    /// updates it.
    pub fn initialize_from_registration(
        &mut self,
        t: f64,
        t_sensor_target: &Pose,
    ) -> Result<(), TrackError> {
        self.initialize(t, t_sensor_target, Vector3::zeros(), Vector3::zeros())?;
        self.seeded = false;
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
            return Ok(TrackOutput::lost(
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
        let scan_w = scan_rate(m.t_target_sensor_start.as_ref(), &m.registration, &scan);
        let (registration, line) = self.held.follow(scan_end, m.registration);
        let held = HeldAxes::of(&registration, line.map(|c| c.sigma_rad), &prediction);
        let counts = (points.len(), m.points_used);
        let fitted = (m.mode, m.compensated, m.start_up, m.rigid_lag_deg);
        let mut out = self.assess(registration, held, fitted, &prediction, scan_end, counts)?;
        out.fallback = m.fallback;
        out.start_up = m.mode != self.config.mode;
        out.points_behind = m.points_behind;
        out.refit = m.refit;
        if out.status == TrackStatus::Tracking && scan_w.is_some() {
            self.scan_w_target = scan_w;
        }
        self.record_tracked(&out);
        out.timings = Timings {
            preprocess_ms: m.preprocess_ms,
            registration_ms: m.registration_ms,
            total_ms: ms(started),
        };
        Ok(out)
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

    /// The registration of `mode` (the frame's: `crate::start_up`), with the
    /// degeneracy handling's threshold in force (hysteresis while a
    /// rotation is held).
    pub(crate) fn dispatch(&self, plan: crate::start_up::FramePlan) -> Dispatch<'_> {
        let following = self.held.following().then(|| self.held.min_lever_arm_m());
        let mut ndt = ndt_params(&self.config, self.holding, following);
        if plan.start_up {
            ndt.max_iterations = ndt.max_iterations.max(self.config.start_up_max_iterations);
        }
        Dispatch {
            start_up_w_target: self.scan_w_target.filter(|_| plan.start_up),
            config: &self.config,
            model: &self.model,
            filter: &self.filter,
            mode: plan.mode,
            ndt,
        }
    }

    /// Quality and consistency checks, filter update, status; `(points_in,
    /// points_used)`: the point counts before and after pre-processing.
    fn assess(
        &mut self,
        registration: Registration,
        held: Option<HeldAxes>,
        (mode, compensated, start_up, rigid_lag_deg): (TrackingMode, bool, bool, Option<f64>),
        prediction: &Prediction,
        t: f64,
        (points_in, points_used): (usize, usize),
    ) -> Result<TrackOutput, TrackError> {
        let measured = registration.t_sensor_target();
        let innovation_rot_deg =
            so3::distance(&measured.rotation, &prediction.pose.rotation).to_degrees();
        let innovation_pos_m = (measured.translation - prediction.pose.translation).norm();
        let information = measurement_information(&registration, self.config.geometric_sigma_m);
        let t_ts = &registration.t_target_sensor;
        let covariance = covariance_sensor_target(t_ts, &information).map(|c| {
            attitude_scaled(&self.config, mode, c, compensated)
                * self.config.measurement_covariance_scale
        });
        let (fused, covariance) = match (&held, covariance) {
            (Some(h), Some(c)) => {
                let (fused, published) = h.covariances(t_ts, &c);
                (Some(fused), Some(published))
            }
            (_, c) => (c, c),
        };
        let nis = self
            .filter
            .innovation(t, &measured, fused.as_ref())
            .map_or(f64::NAN, |o| o.mahalanobis2);
        let mut reasons = quality_issues(&self.config, &registration);
        let loss = &self.config.loss;
        reasons.extend(held_doubt(loss, held.as_ref()));
        reasons.extend(rigid_lag_doubt(loss, mode, rigid_lag_deg));
        let limit =
            self.innovations
                .limit_deg(&loss.innovation, loss.max_innovation_rot_deg, start_up);
        reasons.extend(inconsistency(
            loss,
            limit,
            innovation_rot_deg,
            innovation_pos_m,
        ));
        if reasons.is_empty() && self.seeded {
            self.filter
                .initialize(t, &measured, Vector3::zeros(), Vector3::zeros())?;
            self.seeded = false;
        } else if reasons.is_empty() {
            let outcome = self.filter.update(t, &measured, fused)?;
            if !outcome.fused {
                reasons.push(format!(
                    "filter gate: Mahalanobis² {:.1}",
                    outcome.mahalanobis2
                ));
            }
        }
        let status = self.status_after(&mut reasons);
        if status == TrackStatus::Tracking && !start_up {
            self.innovations
                .record(&self.config.loss.innovation, innovation_rot_deg);
        }
        let (t_sensor_target, covariance) =
            published(self.config.mode, status, measured, covariance, prediction);
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
            nis,
            w_target: estimate.w_target,
            v_sensor: estimate.v_sensor,
            points_in,
            points_used,
            timings: Timings::default(),
            fallback: false,
            start_up: false,
            points_behind: 0,
            refit: false,
            held,
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

    fn declare_lost(
        &mut self,
        prediction: &Prediction,
        points_in: usize,
        reason: String,
        started: Instant,
    ) -> TrackOutput {
        self.lost = true;
        TrackOutput::lost(prediction, points_in, &reason, started)
    }
}
