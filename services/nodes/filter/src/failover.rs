//! Sticky failover between redundant trackers (issue 7): which instance is
//! the *acting* primary of the one-estimate-per-frame selector.
//!
//! Without it, a dead or frozen primary costs one frame deadline on every
//! frame until it is back: the selector waits for the primary's estimate
//! up to the deadline, then takes the standby's. With it:
//!
//! - **Promotion.** When the acting primary misses its deadline (nothing
//!   by the deadline, or only a late estimate) on `promote_after_misses`
//!   consecutive frames, the standby whose good estimate was taken instead
//!   becomes the acting primary: from the next undecided frame on its
//!   estimate is taken on arrival, with no deadline wait.
//! - **Revert.** The *preferred* primary (the configured one, or the one a
//!   swap command named) keeps being offered as a standby. Once it has
//!   delivered a good estimate on time on `revert_after_frames`
//!   consecutive frames, it takes the role back.
//!
//! Choices (documented in [`FailoverPolicy`]'s defaults): two misses, not
//! one, because a single late frame is a hiccup (one slow registration, a
//! loaded machine), not a failure, and promoting on it would flip roles on
//! noise; at 5 Hz two frames are 400 ms, still less than a hang timeout of
//! 500 ms, so the standby is promoted before the supervisor even flags a
//! frozen primary. Revert rather than keep the promoted standby for good,
//! because the deployment chose the preferred primary for a reason (its
//! mode), and the operator's choice should hold once that instance is
//! healthy again; five consecutive good, on-time frames (1 s at 5 Hz) of a
//! restarted primary is the hysteresis that keeps a crash-looping primary
//! from flapping the role every frame. `revert_after_frames = 0` gives the
//! non-revertive variant (the promoted standby stays primary, the old
//! primary is its standby).
//!
//! An *unusable* primary on time (not tracking, inconsistent) is not a
//! miss: the standby's estimate is taken as soon as both are there, so it
//! costs no deadline.

use crate::choice::{Quality, Reason};

/// When the selector moves the primary role by itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FailoverPolicy {
    /// Consecutive frames on which the acting primary misses its deadline
    /// before the standby that replaced it is promoted. 0: never promote
    /// (every frame without the primary waits for the deadline).
    pub promote_after_misses: u32,
    /// Consecutive frames on which the preferred primary, displaced by a
    /// promotion, delivers a good estimate on time before it takes the
    /// role back. 0: never (non-revertive).
    pub revert_after_frames: u32,
}

impl Default for FailoverPolicy {
    /// Promote after 2 misses, revert after 5 good frames (see the module
    /// documentation for why).
    fn default() -> Self {
        Self {
            promote_after_misses: 2,
            revert_after_frames: 5,
        }
    }
}

/// Why the acting primary changed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChangeCause {
    /// The acting primary missed its deadline on this many consecutive
    /// frames; the standby that replaced it was promoted.
    Promoted {
        /// Consecutive misses.
        misses: u32,
    },
    /// The preferred primary delivered good estimates on time on this many
    /// consecutive frames and took the role back.
    Reverted {
        /// Consecutive good, on-time frames.
        frames: u32,
    },
}

/// A change of the acting primary.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RoleChange {
    /// The previous acting primary.
    pub from: String,
    /// The new one.
    pub to: String,
    /// Why.
    pub cause: ChangeCause,
    /// The first frame that may be decided under the new role (the one
    /// after the newest decided frame).
    pub from_frame: u64,
}

/// The preferred and acting primaries and the counters that move the role.
#[derive(Debug, Clone, Default)]
pub struct Roles {
    policy: FailoverPolicy,
    preferred: Option<String>,
    acting: Option<String>,
    /// Consecutive decided frames without the acting primary's estimate by
    /// the deadline.
    misses: u32,
    /// The standby whose good estimate replaced the missing primary most
    /// recently in the current run of misses.
    replacement: Option<String>,
    /// Consecutive frames with a good, on-time estimate of the displaced
    /// preferred primary.
    streak: u32,
    streak_last: Option<u64>,
}

impl Roles {
    /// `primary` both preferred and acting (none: first arrival wins, no
    /// roles).
    pub fn new(primary: Option<String>, policy: FailoverPolicy) -> Self {
        Self {
            policy,
            acting: primary.clone(),
            preferred: primary,
            ..Self::default()
        }
    }

    /// The policy.
    pub fn policy(&self) -> FailoverPolicy {
        self.policy
    }

    /// The instance whose estimates are taken without a deadline wait.
    pub fn acting(&self) -> Option<&str> {
        self.acting.as_deref()
    }

    /// The configured primary, or the one the last swap named.
    pub fn preferred(&self) -> Option<&str> {
        self.preferred.as_deref()
    }

    /// Makes `instance` preferred and acting (a swap), counters cleared.
    pub fn set(&mut self, instance: &str) {
        *self = Self::new(Some(instance.to_string()), self.policy);
    }

    /// Forgets the frame numbering (the selector was reset): the streak
    /// starts again.
    pub fn forget_frames(&mut self) {
        self.streak = 0;
        self.streak_last = None;
    }

    /// An estimate of `instance` for frame `sequence` was offered; `on_time_good`
    /// when it is good and came by its frame's deadline. Returns the
    /// change when the displaced preferred primary takes the role back.
    pub fn observe_offer(
        &mut self,
        instance: &str,
        sequence: u64,
        on_time_good: bool,
        from_frame: u64,
    ) -> Option<RoleChange> {
        let preferred = self.preferred.as_deref()?;
        if instance != preferred || self.acting.as_deref() == Some(preferred) {
            return None;
        }
        match self.streak_last {
            Some(last) if sequence <= last => return None,
            Some(last) if on_time_good && sequence == last + 1 => self.streak += 1,
            _ => self.streak = u32::from(on_time_good),
        }
        self.streak_last = Some(sequence);
        let n = self.policy.revert_after_frames;
        if n == 0 || self.streak < n {
            return None;
        }
        let frames = self.streak;
        let change = self.switch_to(preferred.to_string(), from_frame);
        change.map(|mut c| {
            c.cause = ChangeCause::Reverted { frames };
            c
        })
    }

    /// Frame decided: the estimate of `chosen` (of `quality`) was taken for
    /// `reason`. Call for every decision, in frame order, then [`Self::settle`].
    pub fn observe_decision(&mut self, chosen: &str, quality: Quality, reason: Reason) {
        let Some(acting) = self.acting.as_deref() else {
            return;
        };
        let is_acting = chosen == acting;
        match reason {
            Reason::Primary => {
                self.misses = 0;
                self.replacement = None;
            }
            Reason::PrimaryMissing | Reason::PrimaryLate | Reason::Fallback if !is_acting => {
                self.misses += 1;
                if quality == Quality::Good {
                    self.replacement = Some(chosen.to_string());
                }
            }
            // Late, or the only (unusable) estimate there: a miss without
            // a replacement to promote.
            Reason::PrimaryLate => self.misses += 1,
            Reason::PrimaryMissing
            | Reason::Fallback
            | Reason::PrimaryUnusable(_)
            | Reason::FirstArrival => {}
        }
    }

    /// After a batch of decisions: promotes the replacement when the acting
    /// primary has missed `promote_after_misses` consecutive frames.
    pub fn settle(&mut self, from_frame: u64) -> Option<RoleChange> {
        let k = self.policy.promote_after_misses;
        if k == 0 || self.misses < k {
            return None;
        }
        let misses = self.misses;
        let to = self.replacement.clone()?;
        self.switch_to(to, from_frame).map(|mut c| {
            c.cause = ChangeCause::Promoted { misses };
            c
        })
    }

    fn switch_to(&mut self, to: String, from_frame: u64) -> Option<RoleChange> {
        let from = self.acting.replace(to.clone())?;
        self.misses = 0;
        self.replacement = None;
        self.forget_frames();
        (from != to).then_some(RoleChange {
            from,
            to,
            cause: ChangeCause::Promoted { misses: 0 },
            from_frame,
        })
    }
}
