//! The authoritative relative-motion state, without any bus: what to do
//! with each acquisition result and tracker estimate, and the state to
//! publish.
//!
//! Estimates go through the one-estimate-per-frame selector
//! ([`crate::selector`]); the one chosen for a frame is fused when it is
//! `tracking` and after the filter's time. An accepted acquisition
//! (re)initialises the filter at ω = v = 0 (seed 000 §5.2); a restarted
//! filter resumes from a snapshot, or from the first `tracking` estimate.

use crate::choice::{Candidate, Choice, Offer, Quality, Reason};
use crate::config::FilterServiceConfig;
use crate::error::FilterNodeError;
use crate::failover::RoleChange;
use crate::selector::FrameSelector;
use spacepose_filter::{FilterError, RelativeMotionFilter};
use spacepose_messages::convert::filter::{state_of, zero_rates};
use spacepose_messages::convert::{
    Measurement, acquisition_pose, measurement_from_estimate, prediction_from_state,
};
use spacepose_messages::{AcquisitionResult, FilterState, MessageError, PoseEstimate, WireStatus};
use spacepose_runtime::ServiceConfig;

/// What fusing the estimate chosen for a frame did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EstimateOutcome {
    /// Fused into the filter: publish the new state.
    Fused,
    /// The first registration after an acquisition (or one of the frame
    /// the filter was initialised at, before any update): it replaced the
    /// initial pose, with zero rates, at its own time. Publish the state.
    Reinitialized,
    /// The filter's innovation gate refused it (state unchanged).
    Gated {
        /// Squared Mahalanobis distance of the innovation.
        mahalanobis2: f64,
    },
    /// Not a `tracking` estimate: reported, not fused (as in the tracker).
    NotTracking(WireStatus),
    /// The filter has not been initialised by an acquisition yet (and
    /// `init_from_tracking` is off).
    NotInitialized,
    /// The filter was uninitialised (e.g. just restarted): this `tracking`
    /// estimate initialised it, with zero rates and a wide covariance.
    InitializedFromEstimate,
    /// At or before the time of the current state (and not the initial frame).
    TooOld {
        /// `t_estimate - t_filter` (s).
        dt_s: f64,
    },
}

impl EstimateOutcome {
    /// True when the state changed and should be published.
    pub fn changed_state(self) -> bool {
        matches!(
            self,
            Self::Fused | Self::Reinitialized | Self::InitializedFromEstimate
        )
    }
}

/// An estimate the selector chose for its frame, and what fusing it did.
#[derive(Debug, Clone, PartialEq)]
pub struct Fusion {
    /// Frame sequence.
    pub sequence: u64,
    /// Instance that produced the estimate.
    pub instance: String,
    /// Why the selector chose it.
    pub reason: Reason,
    /// What the fusion did (an error leaves the state unchanged).
    pub outcome: Result<EstimateOutcome, FilterError>,
}

impl Fusion {
    /// True when the state changed and should be published.
    pub fn changed_state(&self) -> bool {
        self.outcome.as_ref().is_ok_and(|o| o.changed_state())
    }
}

/// The filter and its selector: the authoritative relative-motion state.
#[derive(Debug, Clone)]
pub struct Fuser {
    filter: RelativeMotionFilter,
    selector: FrameSelector<Measurement>,
    max_disagreement_rad: f64,
    max_disagreement_m: f64,
    updates: u64,
    /// Time of the last (re)initialisation while no estimate has been fused since.
    fresh_init_t: Option<f64>,
    /// The state is an acquisition's pose, no registration yet: the next
    /// `tracking` estimate restarts the filter at its own pose instead of
    /// updating it, as the tracker's local filter does
    /// (`Tracker::initialize`, docs/design/acquisition-seed.md).
    seeded: bool,
    init_from_tracking: bool,
}

impl Fuser {
    /// An uninitialised state.
    ///
    /// # Errors
    /// An invalid configuration.
    pub fn new(config: &FilterServiceConfig) -> Result<Self, FilterNodeError> {
        config.validate().map_err(FilterNodeError::Config)?;
        Ok(Self {
            filter: RelativeMotionFilter::new(config.filter.clone())?,
            selector: FrameSelector::new(
                config.primary.clone(),
                config.frame_deadline_ms,
                config.selector_window,
            )
            .with_failover(config.failover()),
            max_disagreement_rad: config.max_disagreement_deg.to_radians(),
            max_disagreement_m: config.max_disagreement_m,
            updates: 0,
            fresh_init_t: None,
            seeded: false,
            init_from_tracking: config.init_from_tracking,
        })
    }

    /// The filter.
    pub fn filter(&self) -> &RelativeMotionFilter {
        &self.filter
    }

    /// States changes (initialisations and fused estimates) so far.
    pub fn updates(&self) -> u64 {
        self.updates
    }

    /// The state to publish (uninitialised until an acquisition arrives).
    pub fn state(&self) -> FilterState {
        state_of(&self.filter, self.updates)
    }

    /// The selector of the estimates.
    pub fn selector(&self) -> &FrameSelector<Measurement> {
        &self.selector
    }

    /// (Re)initialises on a successful acquisition, at ω = v = 0 (seed 000
    /// §5.2). Returns whether the state changed. Errors on a bad message.
    pub fn on_acquisition(&mut self, a: &AcquisitionResult) -> Result<bool, FilterNodeError> {
        let Some((t, pose)) = acquisition_pose(a)? else {
            return Ok(false);
        };
        let (v, w) = zero_rates();
        self.filter.initialize(t, &pose, v, w)?;
        self.selector.reset();
        self.fresh_init_t = Some(t);
        self.seeded = true;
        self.updates += 1;
        Ok(true)
    }

    /// Resumes from a persisted state (a snapshot of the previous filter
    /// process, see [`crate::snapshot`]): pose, rates and covariances at
    /// its time. Returns false for an uninitialised state (nothing to
    /// resume); errors on a bad one (the state is unchanged then).
    pub fn restore(&mut self, s: &FilterState) -> Result<bool, FilterNodeError> {
        let Some(p) = prediction_from_state(s)? else {
            return Ok(false);
        };
        self.filter.restore(&p)?;
        self.fresh_init_t = None;
        self.seeded = false;
        self.updates = self.updates.max(s.sequence) + 1;
        Ok(true)
    }

    /// Promotions and reverts of the acting primary since the last call.
    pub fn take_role_changes(&mut self) -> Vec<RoleChange> {
        self.selector.take_role_changes()
    }

    /// Makes `instance` the primary from the next undecided frame on (swap
    /// command); returns the fusions this decides at once.
    pub fn set_primary(&mut self, instance: &str) -> Vec<Fusion> {
        let choices = self.selector.set_primary(instance);
        self.fuse_all(choices)
    }

    /// Offers a tracker estimate received at `now_ns` to the selector and
    /// fuses what it decides (this frame, or older ones waiting for their
    /// deadline). Errors on a bad message (nothing is offered then).
    pub fn on_estimate(
        &mut self,
        e: &PoseEstimate,
        now_ns: i64,
    ) -> Result<(Offer, Vec<Fusion>), MessageError> {
        let m = measurement_from_estimate(e)?;
        let candidate = Candidate {
            instance: e.instance.as_str().to_string(),
            sequence: e.sequence,
            cloud_published_ns: e.cloud_published_ns,
            quality: self.quality(&m),
            payload: m,
        };
        let (offer, choices) = self.selector.offer(candidate, now_ns);
        Ok((offer, self.fuse_all(choices)))
    }

    /// Decides and fuses the frames whose deadline has passed at `now_ns`.
    pub fn poll_deadlines(&mut self, now_ns: i64) -> Vec<Fusion> {
        let choices = self.selector.poll(now_ns);
        self.fuse_all(choices)
    }

    /// Usable for fusion: `tracking` (or `unconfirmed`) and within the disagreement bounds of
    /// the prediction (when there is one after the filter's time).
    fn quality(&self, m: &Measurement) -> Quality {
        if !m.status.is_tracked() {
            return Quality::NotTracking;
        }
        let predicted = match self.filter.time() {
            Some(t) if m.t > t => self.filter.predict_at(m.t).ok(),
            _ => None,
        };
        match predicted {
            Some(p) => {
                let (angle_rad, dist_m) = m.t_sensor_target.error_to(&p.pose);
                if angle_rad > self.max_disagreement_rad || dist_m > self.max_disagreement_m {
                    Quality::Inconsistent
                } else {
                    Quality::Good
                }
            }
            None => Quality::Good,
        }
    }

    fn fuse_all(&mut self, choices: Vec<Choice<Measurement>>) -> Vec<Fusion> {
        choices
            .into_iter()
            .map(|c| Fusion {
                sequence: c.candidate.sequence,
                instance: c.candidate.instance.clone(),
                reason: c.reason,
                outcome: self.fuse(&c.candidate.payload),
            })
            .collect()
    }

    /// Restarts the filter at a registration's pose and time, zero rates.
    fn restart_at(&mut self, m: &Measurement) -> Result<(), FilterError> {
        let (v, w) = zero_rates();
        self.filter.initialize(m.t, &m.t_sensor_target, v, w)?;
        self.seeded = false;
        self.updates += 1;
        Ok(())
    }

    /// Checks and fuses the estimate chosen for a frame. Errors on a filter
    /// failure (the state is then unchanged).
    fn fuse(&mut self, m: &Measurement) -> Result<EstimateOutcome, FilterError> {
        if !m.status.is_tracked() {
            return Ok(EstimateOutcome::NotTracking(m.status));
        }
        let Some(t_filter) = self.filter.time() else {
            if !self.init_from_tracking {
                return Ok(EstimateOutcome::NotInitialized);
            }
            // A restarted filter without a snapshot: the trackers kept
            // tracking on their local filters; resume from their pose.
            let (v, w) = zero_rates();
            self.filter.initialize(m.t, &m.t_sensor_target, v, w)?;
            self.updates += 1;
            return Ok(EstimateOutcome::InitializedFromEstimate);
        };
        if m.t <= t_filter {
            // The acquisition's own frame (or one before it) tracked by the
            // tracker: a registration beats the acquisition's pose.
            if self.fresh_init_t.is_some() {
                self.restart_at(m)?;
                self.fresh_init_t = Some(m.t);
                return Ok(EstimateOutcome::Reinitialized);
            }
            return Ok(EstimateOutcome::TooOld {
                dt_s: m.t - t_filter,
            });
        }
        if self.seeded {
            // The first registration after an acquisition: the rate is
            // learned from registrations only.
            self.restart_at(m)?;
            self.fresh_init_t = None;
            return Ok(EstimateOutcome::Reinitialized);
        }
        let outcome = self.filter.update(m.t, &m.t_sensor_target, m.covariance)?;
        if !outcome.fused {
            return Ok(EstimateOutcome::Gated {
                mahalanobis2: outcome.mahalanobis2,
            });
        }
        self.fresh_init_t = None;
        self.updates += 1;
        Ok(EstimateOutcome::Fused)
    }
}
