//! One estimate per frame (issue 7): with redundant trackers several
//! `PoseEstimate`s arrive for the same cloud sequence, and exactly one of
//! them may reach the filter's fusion.
//!
//! - Without a primary (a single tracker, or roles not configured) the rule
//!   is "first arrival wins".
//! - With a primary (`primary = "tracker-a"` in the filter's config) the
//!   primary's estimate is taken, unless it is **missing** (nothing by the
//!   frame's deadline), **late** (after the deadline, when a standby's was
//!   already taken) or **unusable** (not `tracking`, or inconsistent with the
//!   filter's prediction); then the best standby estimate is taken. Every
//!   other instance is a standby.
//!
//! The frame's deadline is `cloud_published_ns + deadline`: both trackers
//! work on the same cloud, so they carry the same publish time. Decisions are
//! emitted in frame order: deciding frame `k` first decides every older
//! frame still waiting, with what it has.
//!
//! Failover is sticky ([`crate::failover`]): after the primary missed its
//! deadline on a few consecutive frames, the standby that replaced it is
//! promoted and its estimates are taken on arrival; the displaced primary
//! takes the role back once it delivers again.
//!
//! The selector is generic over the payload (the filter node uses the
//! estimate's measurement), pure, and driven by the caller's clock
//! (`now_ns`). Its vocabulary is in [`crate::choice`].

use crate::choice::{Candidate, Choice, Offer, Quality, Reason};
use crate::failover::{FailoverPolicy, RoleChange, Roles};
use std::collections::{BTreeMap, BTreeSet};

#[derive(Debug, Clone)]
struct Pending<T> {
    deadline_ns: i64,
    primary: Option<Candidate<T>>,
    /// The best standby estimate so far (first arrival among equals).
    standby: Option<Candidate<T>>,
}

/// The primary/standby rule over a sliding window of frames.
///
/// A sequence more than `window` behind the newest decided one is `Stale`,
/// except when it is so far behind (more than `2 × window`) that the source
/// has evidently restarted its numbering: the selector then forgets
/// everything and takes it.
#[derive(Debug, Clone)]
pub struct FrameSelector<T> {
    roles: Roles,
    deadline_ns: i64,
    window: u64,
    decided: BTreeSet<u64>,
    pending: BTreeMap<u64, Pending<T>>,
    changes: Vec<RoleChange>,
}

impl<T: Clone> FrameSelector<T> {
    /// A selector with `primary` (none = first arrival wins), a per-frame
    /// deadline (ms after the cloud's publication) and a window of
    /// `window` frames (at least 1), with the default [`FailoverPolicy`].
    pub fn new(primary: Option<String>, deadline_ms: f64, window: usize) -> Self {
        Self {
            roles: Roles::new(primary, FailoverPolicy::default()),
            deadline_ns: (deadline_ms.max(0.0) * 1e6) as i64,
            window: window.max(1) as u64,
            decided: BTreeSet::new(),
            pending: BTreeMap::new(),
            changes: Vec::new(),
        }
    }

    /// The same selector with another failover policy.
    pub fn with_failover(mut self, policy: FailoverPolicy) -> Self {
        let primary = self.roles.preferred().map(str::to_string);
        self.roles = Roles::new(primary, policy);
        self
    }

    /// The acting primary (the preferred one unless a standby was
    /// promoted), if roles are configured.
    pub fn primary(&self) -> Option<&str> {
        self.roles.acting()
    }

    /// The preferred primary: the configured one, or the last swap's.
    pub fn preferred(&self) -> Option<&str> {
        self.roles.preferred()
    }

    /// The changes of the acting primary (promotions, reverts) since the
    /// last call, oldest first.
    pub fn take_role_changes(&mut self) -> Vec<RoleChange> {
        std::mem::take(&mut self.changes)
    }

    /// Makes `instance` the (preferred and acting) primary from the next
    /// undecided frame on (a frame boundary: frames already decided stay
    /// decided). Held estimates change role with it; a good one of the new
    /// primary is decided now.
    pub fn set_primary(&mut self, instance: &str) -> Vec<Choice<T>> {
        self.roles.set(instance);
        let out = self.reassign();
        self.account(out)
    }

    /// The first frame not decided yet.
    fn next_frame(&self) -> u64 {
        self.newest().map_or(0, |n| n + 1)
    }

    /// Sorts the held estimates by the acting primary (after a role
    /// change); decides the frames where it has a good one.
    fn reassign(&mut self) -> Vec<Choice<T>> {
        let Some(instance) = self.roles.acting().map(str::to_string) else {
            return Vec::new();
        };
        let mut ready = Vec::new();
        for (seq, p) in &mut self.pending {
            let mut all: Vec<Candidate<T>> = p.primary.take().into_iter().collect();
            all.extend(p.standby.take());
            for c in all {
                if c.instance == instance.as_str() {
                    p.primary = Some(c);
                } else {
                    p.standby = better_standby(p.standby.take(), c);
                }
            }
            if p.primary
                .as_ref()
                .is_some_and(|c| c.quality == Quality::Good)
            {
                ready.push(*seq);
            }
        }
        let mut out = Vec::new();
        for seq in ready {
            if let Some(c) = self.pending.remove(&seq).and_then(|p| p.primary) {
                out.extend(self.decide(c, Reason::Primary));
            }
        }
        out
    }

    /// The newest decided frame.
    pub fn newest(&self) -> Option<u64> {
        self.decided.last().copied()
    }

    /// The earliest deadline of a frame still waiting (ns), to wake up for.
    pub fn next_deadline_ns(&self) -> Option<i64> {
        self.pending.values().map(|p| p.deadline_ns).min()
    }

    /// Offers an estimate at time `now_ns`; returns what happened to it and
    /// the decisions made (in frame order, possibly for older frames too).
    pub fn offer(&mut self, c: Candidate<T>, now_ns: i64) -> (Offer, Vec<Choice<T>>) {
        let on_time_good = now_ns <= self.deadline_of(&c, now_ns) && c.quality == Quality::Good;
        let from_frame = self.next_frame();
        let mut out = Vec::new();
        if let Some(change) =
            self.roles
                .observe_offer(&c.instance, c.sequence, on_time_good, from_frame)
        {
            self.changes.push(change);
            out = self.reassign();
        }
        let (offer, decided) = self.place(c, now_ns);
        out.extend(decided);
        (offer, self.account(out))
    }

    /// The deadline of `c`'s frame (ns).
    fn deadline_of(&self, c: &Candidate<T>, now_ns: i64) -> i64 {
        let base = if c.cloud_published_ns > 0 {
            c.cloud_published_ns
        } else {
            now_ns
        };
        base.saturating_add(self.deadline_ns)
    }

    /// Tells the roles about `decided` (in frame order); on a promotion,
    /// re-sorts the held estimates and decides what that makes ready.
    fn account(&mut self, mut decided: Vec<Choice<T>>) -> Vec<Choice<T>> {
        let mut done = 0;
        while done < decided.len() {
            for c in &decided[done..] {
                self.roles
                    .observe_decision(&c.candidate.instance, c.candidate.quality, c.reason);
            }
            done = decided.len();
            if let Some(change) = self.roles.settle(self.next_frame()) {
                self.changes.push(change);
                let more = self.reassign();
                decided.extend(more);
            }
        }
        decided
    }

    /// The primary/standby rule for one estimate, under the current roles.
    fn place(&mut self, c: Candidate<T>, now_ns: i64) -> (Offer, Vec<Choice<T>>) {
        if let Some(offer) = self.out_of_window(c.sequence) {
            return (offer, Vec::new());
        }
        let Some(primary) = self.roles.acting().map(str::to_string) else {
            return (Offer::Chosen, self.decide(c, Reason::FirstArrival));
        };
        let deadline_ns = self.deadline_of(&c, now_ns);
        let late = now_ns > deadline_ns;
        let seq = c.sequence;
        let pending = self.pending.entry(seq).or_insert(Pending {
            deadline_ns,
            primary: None,
            standby: None,
        });
        let ready = if c.instance == primary {
            primary_offer(pending, c, late)
        } else {
            standby_offer(pending, c, late)
        };
        match ready {
            Some((offer, chosen, reason)) => {
                self.pending.remove(&seq);
                (offer, self.decide(chosen, reason))
            }
            None => (Offer::Held, self.expire(now_ns)),
        }
    }

    /// `Duplicate` for a decided frame, `Stale` for one behind the window;
    /// a frame so far behind that the source evidently restarted its
    /// numbering resets the selector.
    fn out_of_window(&mut self, sequence: u64) -> Option<Offer> {
        if self.decided.contains(&sequence) {
            return Some(Offer::Duplicate);
        }
        if let Some(newest) = self.newest() {
            let behind = newest.saturating_sub(sequence);
            if behind > 2 * self.window {
                self.reset();
            } else if behind > self.window {
                return Some(Offer::Stale);
            }
        }
        None
    }

    /// Decides every frame whose deadline has passed at `now_ns`.
    pub fn poll(&mut self, now_ns: i64) -> Vec<Choice<T>> {
        let out = self.expire(now_ns);
        self.account(out)
    }

    fn expire(&mut self, now_ns: i64) -> Vec<Choice<T>> {
        let due: Vec<u64> = self
            .pending
            .iter()
            .filter(|(_, p)| p.deadline_ns < now_ns)
            .map(|(s, _)| *s)
            .collect();
        let mut out = Vec::new();
        for seq in due {
            if let Some(p) = self.pending.remove(&seq)
                && let Some((c, reason)) = fallback(p)
            {
                out.extend(self.decide(c, reason));
            }
        }
        out
    }

    /// Records `c` as its frame's decision, after deciding every older
    /// waiting frame (frame order is kept).
    fn decide(&mut self, c: Candidate<T>, reason: Reason) -> Vec<Choice<T>> {
        let older: Vec<u64> = self.pending.range(..c.sequence).map(|(s, _)| *s).collect();
        let mut out = Vec::new();
        for seq in older {
            if let Some(p) = self.pending.remove(&seq)
                && let Some((old, why)) = fallback(p)
            {
                self.mark(old.sequence);
                out.push(Choice {
                    candidate: old,
                    reason: why,
                });
            }
        }
        self.mark(c.sequence);
        out.push(Choice {
            candidate: c,
            reason,
        });
        out
    }

    fn mark(&mut self, sequence: u64) {
        self.decided.insert(sequence);
        if let Some(newest) = self.newest() {
            let oldest_kept = newest.saturating_sub(self.window);
            self.decided = self.decided.split_off(&oldest_kept);
        }
    }

    /// Forgets every frame (e.g. after a re-initialisation); the roles
    /// stay.
    pub fn reset(&mut self) {
        self.decided.clear();
        self.pending.clear();
        self.roles.forget_frames();
    }
}

/// A frame decided by an offer: what happened to the offer, the estimate
/// chosen and why.
type Ready<T> = Option<(Offer, Candidate<T>, Reason)>;

/// The primary's estimate `c` for its frame: chosen when good (late or
/// not), else a good standby's held one instead; otherwise held.
fn primary_offer<T>(p: &mut Pending<T>, c: Candidate<T>, late: bool) -> Ready<T> {
    if c.quality == Quality::Good {
        let reason = if late {
            Reason::PrimaryLate
        } else {
            Reason::Primary
        };
        return Some((Offer::Chosen, c, reason));
    }
    if let Some(s) = p.standby.take_if(|s| s.quality == Quality::Good) {
        return Some((Offer::Superseded, s, Reason::PrimaryUnusable(c.quality)));
    }
    p.primary = Some(c);
    None
}

/// A standby's estimate `c` for its frame: chosen when good and the
/// primary's is unusable or the deadline has passed; otherwise held (the
/// better of the standbys').
fn standby_offer<T>(p: &mut Pending<T>, c: Candidate<T>, late: bool) -> Ready<T> {
    let primary_bad = p
        .primary
        .as_ref()
        .map(|p| p.quality)
        .filter(|q| *q != Quality::Good);
    if c.quality == Quality::Good
        && let Some(q) = primary_bad
    {
        return Some((Offer::Chosen, c, Reason::PrimaryUnusable(q)));
    }
    if late && c.quality == Quality::Good {
        return Some((Offer::Chosen, c, Reason::PrimaryMissing));
    }
    p.standby = better_standby(p.standby.take(), c);
    None
}

/// The better of two standby estimates: a good one beats an unusable one;
/// among equals the first stays.
fn better_standby<T>(old: Option<Candidate<T>>, new: Candidate<T>) -> Option<Candidate<T>> {
    match old {
        Some(o) if o.quality <= new.quality => Some(o),
        _ => Some(new),
    }
}

/// The decision for a frame at its deadline: a good standby, else the
/// primary's (whatever its quality), else the standby's.
fn fallback<T>(p: Pending<T>) -> Option<(Candidate<T>, Reason)> {
    match (p.primary, p.standby) {
        (None, Some(s)) if s.quality == Quality::Good => Some((s, Reason::PrimaryMissing)),
        (Some(pr), Some(s)) if s.quality == Quality::Good => {
            let q = pr.quality;
            Some((s, Reason::PrimaryUnusable(q)))
        }
        (Some(pr), _) => Some((pr, Reason::Fallback)),
        (None, Some(s)) => Some((s, Reason::Fallback)),
        (None, None) => None,
    }
}

#[cfg(test)]
#[path = "selector_tests.rs"]
mod tests;
