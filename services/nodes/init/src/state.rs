//! The init service's decisions, without any bus: when to acquire, and what
//! the tracker's estimates and the acquisition results change.
//!
//! ```text
//!             start
//!               │
//!               ▼
//!           Listening ── an estimate: tracking ──▶ Tracking
//!               │ an estimate: lost, or no estimate in
//!               │ instance_timeout_frames frames
//!               ▼         rejected (f_CONV > f_MAX, too few points):
//!   ┌──▶ Acquiring{not_before} ◀──┐  retry on frame + retry_after_frames
//!   │           │ accepted        │
//!   │           ▼                 │
//!   │   HandedOver{frame} ────────┘ lost on a frame the tracker started
//!   │           │                   after the result was published (or
//!   │           │ tracking          more than handover_frames later)
//!   │           ▼
//!   └─── Tracking ── lost on frame s: Acquiring{not_before: s}
//! ```
//!
//! A frame is lost when no active tracker instance tracks it (redundant
//! trackers: one lost instance beside a tracking one is not a loss). An
//! acquisition never uses a frame older than the loss that triggered it.
//!
//! The service starts by listening: it acquires only once a tracker says
//! it does not track (an uninitialised tracker reports `lost` on every
//! frame), or when no tracker has answered for `instance_timeout_frames`
//! frames. A tracker's estimate of frame k follows ingest's cloud of
//! frame k, so a service (re)started while the suite tracks would
//! otherwise hold a cloud before it heard any estimate, acquire on it, and
//! restart a good track from its acquisition (the chaos test's `kill:init`
//! did exactly that when the restarted service came up).

use crate::error::InitError;
use serde::{Deserialize, Serialize};
use spacepose_messages::{Name, WireStatus};
use std::collections::HashMap;

/// Timing of the state machine, in frames.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct InitConfig {
    /// After a rejected acquisition on frame `k`, the next attempt uses frame
    /// `k + retry_after_frames` or later (>= 1; seed 002 §4.5: wait and try
    /// again on a later frame).
    pub retry_after_frames: u64,
    /// After an accepted result from frame `k`, `lost` estimates of frames up
    /// to `k + handover_frames` are ignored unless the tracker provably
    /// started them after the result was published (it had not applied the
    /// result yet). >= 1.
    pub handover_frames: u64,
    /// A tracker instance whose last estimate is more than this many frames
    /// behind the newest is no longer counted (it died or was removed). >= 1.
    pub instance_timeout_frames: u64,
}

impl Default for InitConfig {
    fn default() -> Self {
        Self {
            retry_after_frames: 1,
            handover_frames: 3,
            instance_timeout_frames: 3,
        }
    }
}

impl InitConfig {
    /// Every count must be >= 1.
    pub fn validate(&self) -> Result<(), InitError> {
        for (name, v) in [
            ("retry_after_frames", self.retry_after_frames),
            ("handover_frames", self.handover_frames),
            ("instance_timeout_frames", self.instance_timeout_frames),
        ] {
            if v == 0 {
                return Err(InitError::InvalidConfig(format!("{name} must be >= 1")));
            }
        }
        Ok(())
    }
}

/// What the state machine needs from a tracker's `PoseEstimate`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimateInfo {
    /// Tracker instance.
    pub instance: Name,
    /// Frame (cloud sequence).
    pub sequence: u64,
    /// Track status.
    pub status: WireStatus,
    /// When the tracker started the frame (`published_ns − total_ms`,
    /// CLOCK_REALTIME ns), when known.
    pub started_ns: Option<i64>,
}

/// Where the service stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Just started: whether the suite tracks is not known yet. The first
    /// tracker estimate decides; with none by the frame
    /// `instance_timeout_frames` after the first one seen, acquire.
    Listening,
    /// A pose is needed: acquire from the next frame numbered `not_before`
    /// or later.
    Acquiring {
        /// First usable frame.
        not_before: u64,
    },
    /// An accepted result from `frame` was published (at `published_ns`,
    /// when known); waiting for the tracker to take it.
    HandedOver {
        /// The frame the pose came from.
        frame: u64,
        /// When the result was published (CLOCK_REALTIME ns).
        published_ns: Option<i64>,
    },
    /// The tracker tracks: nothing to do until it reports `lost`.
    Tracking,
}

/// What a call changed (for the log and the counters).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Event {
    /// Nothing changed.
    None,
    /// At start, a tracker reported no track (or none answered): acquire
    /// from `frame` on.
    NoTrack {
        /// The first frame to acquire on.
        frame: u64,
    },
    /// The tracker tracks (after a hand-over, or on its own).
    TrackerTracking {
        /// The frame it reported.
        frame: u64,
    },
    /// The tracker lost the target on `frame`: acquire from it on.
    LossDetected {
        /// The first lost frame.
        frame: u64,
    },
    /// The tracker did not keep the handed-over pose (lost after it applied it).
    HandoverFailed {
        /// The lost frame.
        frame: u64,
    },
    /// An acquisition was accepted and handed over.
    Accepted {
        /// The frame it used.
        frame: u64,
        /// Frames since the loss (or since the first frame seen at start).
        delay_frames: Option<u64>,
    },
    /// An acquisition failed; the next try uses frame `retry_from` or later.
    Rejected {
        /// The frame it used.
        frame: u64,
        /// First frame of the next try.
        retry_from: u64,
    },
}

/// Counters of the service.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct InitStats {
    /// Acquisitions run.
    pub attempts: u64,
    /// Accepted ones.
    pub accepted: u64,
    /// Rejected ones.
    pub rejected: u64,
    /// Losses detected (the start is not counted).
    pub losses: u64,
    /// Frames from the last loss (or the first frame) to the accepted acquisition.
    pub last_delay_frames: Option<u64>,
}

/// The init service's state machine.
#[derive(Debug, Clone)]
pub struct InitStateMachine {
    config: InitConfig,
    phase: Phase,
    /// Last (frame, status) of each tracker instance.
    instances: HashMap<Name, (u64, WireStatus)>,
    /// Frame the current need for a pose started from (loss, or first frame).
    need_since: Option<u64>,
    /// When the last accepted result was published (CLOCK_REALTIME ns).
    handed_over_ns: Option<i64>,
    stats: InitStats,
}

impl EstimateInfo {
    /// True when the tracker provably started this frame before
    /// `published_ns` (both times known): it had not applied that result.
    fn started_before(&self, published_ns: Option<i64>) -> bool {
        matches!((self.started_ns, published_ns), (Some(s), Some(p)) if s < p)
    }

    /// True when the tracker provably started this frame after
    /// `published_ns`.
    fn started_after(&self, published_ns: Option<i64>) -> bool {
        matches!((self.started_ns, published_ns), (Some(s), Some(p)) if s > p)
    }
}

impl InitStateMachine {
    /// Starts in `Listening`: acquire once a tracker reports no track.
    pub fn new(config: InitConfig) -> Result<Self, InitError> {
        config.validate()?;
        Ok(Self {
            config,
            phase: Phase::Listening,
            instances: HashMap::new(),
            need_since: None,
            handed_over_ns: None,
            stats: InitStats::default(),
        })
    }

    /// The current phase.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// The counters.
    pub fn stats(&self) -> &InitStats {
        &self.stats
    }

    /// True when an acquisition should run on frame `frame`.
    pub fn wants(&self, frame: u64) -> bool {
        matches!(self.phase, Phase::Acquiring { not_before } if frame >= not_before)
    }

    /// Notes that a frame arrived (the start of the first need for a
    /// pose). While listening with no tracker heard for
    /// `instance_timeout_frames` frames, the service acquires.
    pub fn on_frame(&mut self, frame: u64) -> Event {
        let waiting = matches!(self.phase, Phase::Acquiring { .. } | Phase::Listening);
        if self.need_since.is_none() && waiting {
            self.need_since = Some(frame);
        }
        let silent = self
            .need_since
            .is_some_and(|s| frame >= s + self.config.instance_timeout_frames);
        if self.phase == Phase::Listening && silent {
            self.phase = Phase::Acquiring { not_before: frame };
            return Event::NoTrack { frame };
        }
        Event::None
    }

    /// A tracker estimate.
    pub fn on_estimate(&mut self, e: &EstimateInfo) -> Event {
        self.instances.insert(e.instance, (e.sequence, e.status));
        let frame = e.sequence;
        let tracked = self.suite_tracks(frame);
        match self.phase {
            Phase::Listening if tracked => {
                self.phase = Phase::Tracking;
                self.need_since = None;
                Event::TrackerTracking { frame }
            }
            Phase::Listening => {
                self.phase = Phase::Acquiring { not_before: frame };
                Event::NoTrack { frame }
            }
            Phase::Tracking if !tracked => {
                self.stats.losses += 1;
                self.need(frame);
                Event::LossDetected { frame }
            }
            Phase::Acquiring { not_before } if tracked && frame >= not_before => {
                self.phase = Phase::Tracking;
                Event::TrackerTracking { frame }
            }
            Phase::HandedOver { frame: from, .. } if tracked && frame > from => {
                self.phase = Phase::Tracking;
                Event::TrackerTracking { frame }
            }
            Phase::HandedOver {
                frame: from,
                published_ns,
            } if !tracked && frame > from => {
                if e.started_after(published_ns) || frame > from + self.config.handover_frames {
                    self.stats.losses += 1;
                    self.need(frame);
                    Event::HandoverFailed { frame }
                } else {
                    Event::None
                }
            }
            _ => Event::None,
        }
    }

    /// The acquisition on `frame` is done: `accepted` and published at
    /// `published_ns` (CLOCK_REALTIME ns, when known).
    pub fn on_acquisition(
        &mut self,
        frame: u64,
        accepted: bool,
        published_ns: Option<i64>,
    ) -> Event {
        self.stats.attempts += 1;
        if accepted {
            self.stats.accepted += 1;
            let delay_frames = self.need_since.map(|s| frame.saturating_sub(s));
            self.stats.last_delay_frames = delay_frames;
            self.need_since = None;
            self.handed_over_ns = published_ns;
            self.phase = Phase::HandedOver {
                frame,
                published_ns,
            };
            Event::Accepted {
                frame,
                delay_frames,
            }
        } else {
            self.stats.rejected += 1;
            let retry_from = frame + self.config.retry_after_frames;
            self.phase = Phase::Acquiring {
                not_before: retry_from,
            };
            Event::Rejected { frame, retry_from }
        }
    }

    /// True when `e` is an estimate of the current track: not one the
    /// tracker provably started before the last accepted result went out.
    pub fn of_current_track(&self, e: &EstimateInfo) -> bool {
        !e.started_before(self.handed_over_ns)
    }

    fn need(&mut self, frame: u64) {
        self.phase = Phase::Acquiring { not_before: frame };
        self.need_since = Some(frame);
    }

    /// True when an active instance tracks (or tracks with doubts): its
    /// last estimate is `tracking`/`degraded` and at most
    /// `instance_timeout_frames` behind `frame`.
    fn suite_tracks(&self, frame: u64) -> bool {
        self.instances.values().any(|&(seq, status)| {
            seq + self.config.instance_timeout_frames >= frame && status != WireStatus::Lost
        })
    }
}

#[cfg(test)]
#[path = "state_tests.rs"]
mod tests;
