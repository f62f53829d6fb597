//! The filter service's logic without any bus: what to do with each
//! acquisition result and tracker estimate, and the state to publish.
//! `src/main.rs` only moves messages between the bus and [`FilterNode`].

use crate::config::FilterConfig;
use crate::error::FilterError;
use crate::failover::{FailoverPolicy, RoleChange};
use crate::filter::RelativeMotionFilter;
use crate::selector::{Candidate, Choice, FrameSelector, Offer, Quality, Reason};
use crate::wire::{
    Measurement, acquisition_pose, measurement_from_estimate, prediction_from_state, state_of,
    zero_rates,
};
use serde::{Deserialize, Serialize};
use spacepose_messages::{AcquisitionResult, FilterState, PoseEstimate, WireStatus};

/// Configuration of the `spacepose-filter` service (TOML).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FilterServiceConfig {
    /// Filter tuning. The default turns the innovation gate off, as the
    /// tracker's own filter does: the registration covariance is
    /// over-confident, and the tracker already rejects inconsistent frames
    /// (they arrive as `degraded` and are not fused).
    pub filter: FilterConfig,
    /// Period of the `FilterState` heartbeat (ms), so late joiners (a
    /// restarted tracker, telemetry) get the state without waiting for an
    /// update. 0 disables it.
    pub state_period_ms: u64,
    /// Frames remembered by the one-estimate-per-frame selector.
    pub selector_window: usize,
    /// The primary tracker instance of a redundant deployment (e.g.
    /// `"tracker-a"`); every other instance is a standby. None: the first
    /// estimate of each frame wins. A swap command changes it at run time.
    pub primary: Option<String>,
    /// Per-frame deadline (ms after the cloud's publication by ingest): a
    /// primary estimate later than this is replaced by a standby's.
    pub frame_deadline_ms: f64,
    /// Sticky failover: after the acting primary missed its deadline on
    /// this many consecutive frames, the standby that replaced it is
    /// promoted (its estimates are then taken without waiting). 0: never.
    /// Default 2 (see [`crate::failover`]).
    pub promote_after_misses: u32,
    /// The displaced primary takes the role back after this many
    /// consecutive frames with a good estimate on time. 0: never (the
    /// promoted standby stays primary). Default 5.
    pub revert_after_frames: u32,
    /// A `tracking` estimate further than this from the filter's
    /// prediction (deg) is inconsistent: a standby's is preferred.
    pub max_disagreement_deg: f64,
    /// Same, on the position (m).
    pub max_disagreement_m: f64,
    /// File the state is persisted to after every change, and restored
    /// from at start when fresh (a restarted filter resumes with its
    /// predecessor's pose, rates and covariances). `spacepose up` sets
    /// `{run dir}/{instance}.filterstate`. None: no snapshot.
    pub snapshot_file: Option<std::path::PathBuf>,
    /// A snapshot written longer ago than this (s, wall clock) is ignored.
    pub snapshot_max_age_s: f64,
    /// When uninitialised (no fresh snapshot, no acquisition yet), start
    /// from the first `tracking` estimate the selector chooses, with zero
    /// rates and the initial covariance of `filter` (as an acquisition
    /// does, seed 000 §5.2), instead of waiting for the next acquisition.
    pub init_from_tracking: bool,
}

impl Default for FilterServiceConfig {
    fn default() -> Self {
        Self {
            filter: FilterConfig::default(),
            state_period_ms: 500,
            selector_window: 64,
            primary: None,
            frame_deadline_ms: 100.0,
            promote_after_misses: FailoverPolicy::default().promote_after_misses,
            revert_after_frames: FailoverPolicy::default().revert_after_frames,
            max_disagreement_deg: 10.0,
            max_disagreement_m: 0.5,
            snapshot_file: None,
            snapshot_max_age_s: 10.0,
            init_from_tracking: true,
        }
    }
}

impl FilterServiceConfig {
    /// The failover policy of the selector.
    pub fn failover(&self) -> FailoverPolicy {
        FailoverPolicy {
            promote_after_misses: self.promote_after_misses,
            revert_after_frames: self.revert_after_frames,
        }
    }

    /// Checks every value.
    pub fn validate(&self) -> Result<(), FilterError> {
        self.filter.validate()?;
        if self.selector_window == 0 {
            return Err(FilterError::InvalidConfig(
                "selector_window must be >= 1".into(),
            ));
        }
        let positive = [
            ("frame_deadline_ms", self.frame_deadline_ms),
            ("max_disagreement_deg", self.max_disagreement_deg),
            ("max_disagreement_m", self.max_disagreement_m),
            ("snapshot_max_age_s", self.snapshot_max_age_s),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(FilterError::InvalidConfig(format!(
                    "{name} = {v} must be finite and > 0"
                )));
            }
        }
        if let Some(p) = &self.primary
            && spacepose_messages::Name::new(p).is_err()
        {
            return Err(FilterError::InvalidConfig(format!(
                "primary = {p:?} is not an instance name"
            )));
        }
        Ok(())
    }
}

/// What [`FilterNode::on_estimate`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EstimateOutcome {
    /// Fused into the filter: publish the new state.
    Fused,
    /// The estimate refers to the time the filter was (re)initialised at,
    /// before any update: it replaced the initial pose. Publish the state.
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

/// The filter service: the authoritative relative-motion state.
#[derive(Debug, Clone)]
pub struct FilterNode {
    filter: RelativeMotionFilter,
    selector: FrameSelector<Measurement>,
    max_disagreement_rad: f64,
    max_disagreement_m: f64,
    updates: u64,
    /// Time of the last (re)initialisation while no estimate has been fused since.
    fresh_init_t: Option<f64>,
    init_from_tracking: bool,
}

impl FilterNode {
    /// An uninitialised node.
    pub fn new(config: &FilterServiceConfig) -> Result<Self, FilterError> {
        config.validate()?;
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

    /// (Re)initialises on a successful acquisition, at ω = v = 0 (seed 000
    /// §5.2). Returns whether the state changed. Errors on a bad message.
    pub fn on_acquisition(&mut self, a: &AcquisitionResult) -> Result<bool, FilterError> {
        let Some((t, pose)) = acquisition_pose(a)? else {
            return Ok(false);
        };
        let (v, w) = zero_rates();
        self.filter.initialize(t, &pose, v, w)?;
        self.selector.reset();
        self.fresh_init_t = Some(t);
        self.updates += 1;
        Ok(true)
    }

    /// Resumes from a persisted state (a snapshot of the previous filter
    /// process, see [`crate::snapshot`]): pose, rates and covariances at
    /// its time. Returns false for an uninitialised state (nothing to
    /// resume); errors on a bad one (the node is unchanged then).
    pub fn restore(&mut self, s: &FilterState) -> Result<bool, FilterError> {
        let Some(p) = prediction_from_state(s)? else {
            return Ok(false);
        };
        self.filter.restore(&p)?;
        self.fresh_init_t = None;
        self.updates = self.updates.max(s.sequence) + 1;
        Ok(true)
    }

    /// The acting primary instance of the selector (None: first arrival
    /// wins): the preferred one, unless a standby was promoted.
    pub fn primary(&self) -> Option<&str> {
        self.selector.primary()
    }

    /// The preferred primary (configured, or named by the last swap).
    pub fn preferred_primary(&self) -> Option<&str> {
        self.selector.preferred()
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

    /// The earliest frame deadline the node waits for (ns, CLOCK_REALTIME):
    /// call [`Self::poll`] then.
    pub fn next_deadline_ns(&self) -> Option<i64> {
        self.selector.next_deadline_ns()
    }

    /// Offers a tracker estimate received at `now_ns` to the
    /// one-estimate-per-frame selector and fuses what it decides (this
    /// frame, or older ones waiting for their deadline). Errors on a bad
    /// message (nothing is offered then).
    pub fn on_estimate(
        &mut self,
        e: &PoseEstimate,
        now_ns: i64,
    ) -> Result<(Offer, Vec<Fusion>), FilterError> {
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

    /// Decides and fuses the frames whose deadline has passed.
    pub fn poll(&mut self, now_ns: i64) -> Vec<Fusion> {
        let choices = self.selector.poll(now_ns);
        self.fuse_all(choices)
    }

    /// Usable for fusion: `tracking` and within the disagreement bounds of
    /// the prediction (when there is one after the filter's time).
    fn quality(&self, m: &Measurement) -> Quality {
        if m.status != WireStatus::Tracking {
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

    /// Checks and fuses the estimate chosen for a frame. Errors on a filter
    /// failure (the state is then unchanged).
    fn fuse(&mut self, m: &Measurement) -> Result<EstimateOutcome, FilterError> {
        if m.status != WireStatus::Tracking {
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
                let (v, w) = zero_rates();
                self.filter.initialize(m.t, &m.t_sensor_target, v, w)?;
                self.fresh_init_t = Some(m.t);
                self.updates += 1;
                return Ok(EstimateOutcome::Reinitialized);
            }
            return Ok(EstimateOutcome::TooOld {
                dt_s: m.t - t_filter,
            });
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

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use spacepose_geometry::{Pose, so3};

    /// The documented example parses and shows the library defaults.
    #[test]
    fn the_deploy_example_is_valid() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../deploy/examples/filter.toml"
        );
        let text = std::fs::read_to_string(path).unwrap();
        let c: FilterServiceConfig = toml::from_str(&text).unwrap();
        c.filter.validate().unwrap();
        // The example's [filter] section leaves the gate out: off.
        assert_eq!(c.filter.gate_mahalanobis2, None);
        assert_eq!(c.filter, FilterServiceConfig::default().filter);
        let d = FilterConfig::default();
        assert_eq!(c.filter.q_pos, d.q_pos);
        assert_eq!(
            c.filter.registration_covariance_scale,
            d.registration_covariance_scale
        );
    }

    fn pose_at(t: f64) -> Pose {
        Pose::new(
            so3::exp(&Vector3::new(0.0, 0.0, 0.1 * t)),
            Vector3::new(0.0, 0.0, 20.0 - 0.1 * t),
        )
    }

    fn estimate(seq: u64, t: f64, status: WireStatus) -> PoseEstimate {
        let mut e = PoseEstimate::new();
        e.sequence = seq;
        e.t_s = t;
        e.status = status as u8;
        e.set_pose(&pose_at(t));
        e
    }

    /// Offers `e` (first arrival wins: no primary) and returns the offer and
    /// the outcome of its fusion, if it was chosen.
    fn offer(
        node: &mut FilterNode,
        e: &PoseEstimate,
    ) -> Result<(Offer, Option<EstimateOutcome>), FilterError> {
        let (o, fusions) = node.on_estimate(e, 0)?;
        assert!(fusions.len() <= 1);
        let outcome = fusions.into_iter().next().map(|f| f.outcome).transpose()?;
        Ok((o, outcome))
    }

    fn fused(node: &mut FilterNode, e: &PoseEstimate) -> EstimateOutcome {
        offer(node, e).unwrap().1.unwrap()
    }

    fn acquisition(t: f64) -> AcquisitionResult {
        let mut a = AcquisitionResult::new();
        a.success = 1;
        a.t_s = t;
        a.set_pose(&pose_at(t));
        a
    }

    #[test]
    fn acquisition_then_tracking_estimates_are_fused() {
        let config = FilterServiceConfig {
            init_from_tracking: false,
            ..FilterServiceConfig::default()
        };
        let mut node = FilterNode::new(&config).unwrap();
        assert_eq!(node.state().initialized, 0);
        let e1 = estimate(1, 1.0, WireStatus::Tracking);
        assert_eq!(fused(&mut node, &e1), EstimateOutcome::NotInitialized);
        let mut failed = acquisition(0.0);
        failed.success = 0;
        assert!(!node.on_acquisition(&failed).unwrap());
        assert!(node.on_acquisition(&acquisition(0.0)).unwrap());
        for k in 1..6u64 {
            let e = estimate(k, k as f64, WireStatus::Tracking);
            assert_eq!(fused(&mut node, &e), EstimateOutcome::Fused);
            assert_eq!(offer(&mut node, &e).unwrap(), (Offer::Duplicate, None));
        }
        let s = node.state();
        assert_eq!((s.initialized, s.sequence, s.t_s), (1, 6, 5.0));
        // The filter learnt the rotation rate (0.1 rad/s about z, sensor frame
        // = target frame here since R is about z).
        assert!((s.w_target[2] - 0.1).abs() < 0.05, "{:?}", s.w_target);
    }

    #[test]
    fn degraded_lost_old_and_bad_estimates_change_nothing() {
        let mut node = FilterNode::new(&FilterServiceConfig::default()).unwrap();
        node.on_acquisition(&acquisition(0.0)).unwrap();
        fused(&mut node, &estimate(1, 1.0, WireStatus::Tracking));
        let before = node.state();
        for status in [WireStatus::Degraded, WireStatus::Lost] {
            let e = estimate(2 + status as u64, 2.0, status);
            assert_eq!(fused(&mut node, &e), EstimateOutcome::NotTracking(status));
        }
        let old = estimate(9, 0.5, WireStatus::Tracking);
        assert!(matches!(
            fused(&mut node, &old),
            EstimateOutcome::TooOld { .. }
        ));
        let mut bad = estimate(10, 3.0, WireStatus::Tracking);
        bad.p_sensor_target[0] = f64::NAN;
        assert!(node.on_estimate(&bad, 0).is_err());
        assert_eq!(node.state(), before);
    }

    #[test]
    fn the_acquisition_frame_itself_replaces_the_initial_pose() {
        let mut node = FilterNode::new(&FilterServiceConfig::default()).unwrap();
        node.on_acquisition(&acquisition(2.0)).unwrap();
        let mut e = estimate(2, 2.0, WireStatus::Tracking);
        e.p_sensor_target[2] += 0.05;
        assert_eq!(fused(&mut node, &e), EstimateOutcome::Reinitialized);
        assert_eq!(node.state().p_sensor_target, e.p_sensor_target);
        let next = estimate(3, 3.0, WireStatus::Tracking);
        assert_eq!(fused(&mut node, &next), EstimateOutcome::Fused);
        // After a fused update the same time is simply too old.
        let again = estimate(4, 3.0, WireStatus::Tracking);
        assert!(matches!(
            fused(&mut node, &again),
            EstimateOutcome::TooOld { .. }
        ));
    }

    fn redundant_estimate(instance: &str, seq: u64, p: &Pose) -> PoseEstimate {
        let mut e = estimate(seq, seq as f64, WireStatus::Tracking);
        e.instance = spacepose_messages::Name::new(instance).unwrap();
        e.cloud_published_ns = seq as i64 * 1_000_000_000;
        e.set_pose(p);
        e
    }

    #[test]
    fn an_inconsistent_primary_gives_way_to_the_standby_and_a_swap_moves_the_role() {
        let config = FilterServiceConfig {
            primary: Some("tracker-a".into()),
            ..FilterServiceConfig::default()
        };
        let mut node = FilterNode::new(&config).unwrap();
        node.on_acquisition(&acquisition(0.0)).unwrap();
        let ms = 1_000_000;
        for k in 1..4u64 {
            let t0 = k as i64 * 1_000_000_000;
            let b = redundant_estimate("tracker-b", k, &pose_at(k as f64));
            assert_eq!(node.on_estimate(&b, t0 + 5 * ms).unwrap().0, Offer::Held);
            let a = redundant_estimate("tracker-a", k, &pose_at(k as f64));
            let (o, f) = node.on_estimate(&a, t0 + 10 * ms).unwrap();
            assert_eq!((o, f[0].instance.as_str()), (Offer::Chosen, "tracker-a"));
            assert_eq!(f[0].outcome, Ok(EstimateOutcome::Fused));
        }
        // Frame 4: the primary is 20° off the prediction.
        let t0 = 4_000_000_000;
        let mut off = pose_at(4.0);
        off.rotation = so3::exp(&Vector3::new(0.35, 0.0, 0.0)) * off.rotation;
        let a = redundant_estimate("tracker-a", 4, &off);
        assert_eq!(node.on_estimate(&a, t0 + 5 * ms).unwrap().0, Offer::Held);
        let b = redundant_estimate("tracker-b", 4, &pose_at(4.0));
        let (_, f) = node.on_estimate(&b, t0 + 10 * ms).unwrap();
        assert_eq!(f[0].instance, "tracker-b");
        assert_eq!(f[0].reason, Reason::PrimaryUnusable(Quality::Inconsistent));
        assert!(f[0].changed_state());
        // Frame 5: the primary is missing; the standby is fused at the deadline.
        let t0 = 5_000_000_000;
        let b = redundant_estimate("tracker-b", 5, &pose_at(5.0));
        node.on_estimate(&b, t0 + 5 * ms).unwrap();
        assert_eq!(node.next_deadline_ns(), Some(t0 + 100 * ms));
        assert!(node.poll(t0 + 50 * ms).is_empty());
        let f = node.poll(t0 + 101 * ms);
        assert_eq!((f[0].sequence, f[0].reason), (5, Reason::PrimaryMissing));
        assert_eq!(node.state().t_s, 5.0);
        // A swap makes tracker-b the primary: frame 6 needs no deadline.
        assert!(node.set_primary("tracker-b").is_empty());
        assert_eq!(node.primary(), Some("tracker-b"));
        let b = redundant_estimate("tracker-b", 6, &pose_at(6.0));
        let (o, f) = node.on_estimate(&b, 6_000_000_000 + 5 * ms).unwrap();
        assert_eq!((o, f[0].reason), (Offer::Chosen, Reason::Primary));
    }

    #[test]
    fn selector_settings_are_validated() {
        for bad in [
            FilterServiceConfig {
                frame_deadline_ms: 0.0,
                ..FilterServiceConfig::default()
            },
            FilterServiceConfig {
                max_disagreement_deg: f64::NAN,
                ..FilterServiceConfig::default()
            },
            FilterServiceConfig {
                primary: Some("no spaces allowed".into()),
                ..FilterServiceConfig::default()
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        let c: FilterServiceConfig =
            toml::from_str("primary = \"tracker-a\"\nframe_deadline_ms = 80.0\n").unwrap();
        assert_eq!(c.primary.as_deref(), Some("tracker-a"));
        c.validate().unwrap();
        assert_eq!(c.failover(), FailoverPolicy::default());
        let c: FilterServiceConfig =
            toml::from_str("promote_after_misses = 3\nrevert_after_frames = 0\n").unwrap();
        assert_eq!(
            c.failover(),
            FailoverPolicy {
                promote_after_misses: 3,
                revert_after_frames: 0
            }
        );
    }
}
