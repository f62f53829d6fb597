//! One frame's measurement: the frame path, the mode's registration and,
//! when CT-NDT stalled, its fallback; or why there is none.

use super::Tracker;
use super::scan::{ms, scan_rate};
use crate::assess::stalled;
use crate::dispatch::{Fitted, LastPose};
use crate::mode::TrackingMode;
use crate::pipeline::Prepared;
use crate::start_up::{FramePlan, frame_plan};
use spacepose_filter::Prediction;
use spacepose_geometry::{Point, Pose};
use spacepose_registration::{Registration, ScanTimes};
use std::time::Instant;

/// A frame's registration and how it was obtained ([`Tracker::measure`]).
pub(super) struct Measured {
    pub(super) registration: Registration,
    /// The cloud was motion-compensated by the prediction (Eq. 12).
    pub(super) compensated: bool,
    /// Points the registration saw.
    pub(super) points_used: usize,
    /// Fitted by the stall fallback.
    pub(super) fallback: bool,
    /// The frame's registration (`crate::start_up::frame_plan`).
    pub(super) mode: TrackingMode,
    /// The frame is in the start-up (`crate::start_up::frame_plan`).
    pub(super) start_up: bool,
    /// `t_target_sensor` at the scan start, when CT-NDT fitted the scan
    /// with two poses.
    pub(super) t_target_sensor_start: Option<Pose>,
    pub(super) preprocess_ms: f64,
    /// Points the visibility gate dropped.
    pub(super) points_behind: usize,
    /// Registered again on the cloud gated at the first fit
    /// ([`crate::VisibilityConfig::refit`]).
    pub(super) refit: bool,
    /// Registration, the fallback included.
    pub(super) registration_ms: f64,
    /// The lag of a rigid fit ([`rigid_lag_deg`]); `None` in `deblur` and
    /// `ct-ndt` and for a compensated cloud.
    pub(super) rigid_lag_deg: Option<f64>,
}

/// The target's turn (deg) at the predicted rate between the points' mean
/// acquisition time and the scan's end: how far a fit of one pose to the
/// whole scan (`ndt`, `icp`: seed 000 Fig. 2), the pose of about the mean
/// return time, lags the scan end it is published for
/// ([`crate::assess::rigid_lag_doubt`]).
fn rigid_lag_deg(cloud: &[Point], prediction: &Prediction, scan: &ScanTimes) -> f64 {
    let mean_t = cloud.iter().map(|p| p.t).sum::<f64>() / cloud.len().max(1) as f64;
    (prediction.w_target.norm() * (scan.end_s - mean_t)).to_degrees()
}

/// Why a frame carried no measurement, and what is known of it.
pub(super) struct Missing {
    pub(super) reason: String,
    /// Points left after pre-processing (0 when it failed or was not the
    /// cause).
    pub(super) points_used: usize,
    /// 0 when pre-processing was not the cause.
    pub(super) preprocess_ms: f64,
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

/// What a registration of the frame is given besides its cloud.
#[derive(Clone, Copy)]
struct FitContext<'a> {
    plan: FramePlan,
    compensated: bool,
    prediction: &'a Prediction,
    last: &'a LastPose,
    scan: &'a ScanTimes,
}

/// The prediction the second gate uses: the fitted end pose and, where
/// CT-NDT fitted the scan with two poses, the rate between them (the
/// prediction's velocities otherwise), with no uncertainty of its own (the
/// gate's `pose_allowance_deg` covers a fit's).
fn fitted_prediction(prediction: &Prediction, fitted: &Fitted, scan: &ScanTimes) -> Prediction {
    let start = fitted.t_target_sensor_start.as_ref();
    let w_target = scan_rate(start, &fitted.registration, scan).unwrap_or(prediction.w_target);
    let v_sensor = start
        .map(|s| {
            let p0 = s.inverse().translation;
            let p1 = fitted.registration.t_sensor_target().translation;
            (p1 - p0) / (scan.end_s - scan.start_s)
        })
        .filter(|v| v.iter().all(|c| c.is_finite()))
        .unwrap_or(prediction.v_sensor);
    Prediction {
        t: scan.end_s,
        pose: fitted.registration.t_sensor_target(),
        v_sensor,
        w_target,
        covariance: nalgebra::Matrix6::zeros(),
        ..*prediction
    }
}

impl Tracker {
    /// Pre-processing and registration of one frame (with the stall
    /// fallback), or why there is no measurement: pre-processing failed, too
    /// few points are left (`loss.min_points`: the target is not in view),
    /// or the registration failed.
    pub(super) fn measure(
        &mut self,
        points: &[Point],
        prediction: &Prediction,
        last: &LastPose,
        scan: &ScanTimes,
    ) -> Result<Measured, Missing> {
        let pre = Instant::now();
        let c = &self.config;
        let plan = frame_plan(c, prediction, scan);
        let mode = plan.mode;
        let Prepared { cloud, compensated } = self
            .pipeline
            .prepare(points, mode, c.ct_ndt_min_points, prediction)
            .map_err(|e| Missing::because(e.to_string()))?;
        let (cloud, points_behind) = self
            .visible(cloud, compensated, prediction, scan)
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
        let fitted = self
            .dispatch(plan)
            .register(&cloud, compensated, prediction, last, scan)
            .map_err(|e| Missing::because(e.to_string()))?;
        let context = FitContext {
            plan,
            compensated,
            prediction,
            last,
            scan,
        };
        let second = (self.config.visibility.refit && plan.start_up)
            .then(|| self.refit(&cloud, &fitted, &context))
            .flatten();
        let refit = second.is_some();
        let rigid_lag_deg = (!mode.uses_prediction() && !compensated)
            .then(|| rigid_lag_deg(&cloud, prediction, scan));
        let (fitted, points_behind, registered) = match second {
            Some((fit, behind, kept)) => (fit, points_behind + behind, kept),
            None => (fitted, points_behind, cloud.len()),
        };
        let (registration, start) = (fitted.registration, fitted.t_target_sensor_start);
        let fallback = self.stall_fallback(points, &registration, &context);
        let (registration, compensated, points_used, fallback, start) = match fallback {
            Some((r, n)) => (r, true, n, true, None),
            None => (registration, compensated, registered, false, start),
        };
        Ok(Measured {
            registration,
            compensated,
            points_used,
            fallback,
            mode,
            start_up: plan.start_up,
            t_target_sensor_start: start,
            preprocess_ms,
            points_behind,
            refit,
            registration_ms: ms(reg_start),
            rigid_lag_deg,
        })
    }

    /// [`crate::VisibilityConfig::refit`], in the start-up: the gate again
    /// on the registered `cloud`, at the pose (and, for CT-NDT, the scan's
    /// motion) the `first` registration found, with the allowance of a
    /// fitted pose rather than of a prediction. When it drops
    /// `refit_min_fraction` of the cloud, the frame is registered again on
    /// what it keeps, from the same guess and priors: the fit, not the
    /// prediction, says where the surface is. Returns that fit, the points
    /// the second gate dropped and the points it kept; `None` when there
    /// was no second registration.
    fn refit(
        &mut self,
        cloud: &[Point],
        first: &Fitted,
        c: &FitContext<'_>,
    ) -> Option<(Fitted, usize, usize)> {
        let at_fit = fitted_prediction(c.prediction, first, c.scan);
        let config = &self.config.visibility;
        let min_dropped = (config.refit_min_fraction * cloud.len() as f64)
            .ceil()
            .max(1.0);
        let gated = self
            .model
            .visibility
            .gate(cloud.to_vec(), c.compensated, &at_fit, config)
            .ok()
            .filter(|g| !g.overruled && g.behind as f64 >= min_dropped)?;
        let second = self
            .dispatch(c.plan)
            .register(&gated.points, c.compensated, c.prediction, c.last, c.scan)
            .ok()?;
        tracing::debug!(
            t = c.scan.end_s,
            dropped = gated.behind,
            "registered again on the cloud gated at the first fit"
        );
        Some((second, gated.behind, gated.points.len()))
    }

    /// The visibility gate ([`crate::visibility`]) on a prepared cloud: the
    /// points kept and how many were dropped.
    fn visible(
        &self,
        cloud: Vec<Point>,
        at_scan_end: bool,
        prediction: &Prediction,
        scan: &ScanTimes,
    ) -> Result<(Vec<Point>, usize), crate::TrackError> {
        let gated =
            self.model
                .visibility
                .gate(cloud, at_scan_end, prediction, &self.config.visibility)?;
        if gated.overruled {
            tracing::debug!(
                t = scan.end_s,
                behind = gated.behind,
                "visibility gate overruled: most points lie behind the model at the prediction"
            );
            return Ok((gated.points, 0));
        }
        Ok((gated.points, gated.behind))
    }

    /// [`TrackerConfig::ct_ndt_stall_fallback`]: when CT-NDT stalled, the
    /// one-pose fit of the cloud compensated by the prediction (`deblur`'s
    /// registration) and its point count; `None` otherwise, or when that
    /// fit fails too (the stalled result then stands, and is doubted).
    fn stall_fallback(
        &mut self,
        points: &[Point],
        registration: &Registration,
        context: &FitContext<'_>,
    ) -> Option<(Registration, usize)> {
        let FitContext {
            plan,
            compensated,
            prediction,
            last,
            scan,
        } = *context;
        let c = &self.config;
        if plan.mode != TrackingMode::CtNdt
            || compensated
            || !c.ct_ndt_stall_fallback
            || !stalled(&c.loss, registration)
        {
            return None;
        }
        let cloud = self.pipeline.compensated(points, prediction).ok()?;
        let (cloud, _) = self.visible(cloud, true, prediction, scan).ok()?;
        match self
            .dispatch(plan)
            .register(&cloud, true, prediction, last, scan)
        {
            Ok(r) => {
                let r = r.registration;
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
}
