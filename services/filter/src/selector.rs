//! One estimate per frame: with redundant trackers (issue 7) several
//! `PoseEstimate`s arrive for the same cloud sequence; the filter must fuse
//! only one of them. The rule for now is "first arrival wins".

use std::collections::BTreeSet;

/// What the selector decided for an estimate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Selection {
    /// The first estimate of its sequence: use it.
    Selected,
    /// Another estimate of this sequence was selected before: drop it.
    Duplicate,
    /// Older than the remembered window (a straggler): drop it.
    Stale,
}

/// Remembers the sequences already selected within a sliding window.
///
/// A sequence more than `window` behind the newest one is `Stale`, except
/// when it is so far behind (more than `2 × window`) that the source has
/// evidently restarted its numbering: the selector then forgets everything
/// and selects it.
#[derive(Debug, Clone)]
pub struct EstimateSelector {
    window: u64,
    seen: BTreeSet<u64>,
}

impl EstimateSelector {
    /// A selector remembering `window` sequences (at least 1).
    pub fn new(window: usize) -> Self {
        Self {
            window: window.max(1) as u64,
            seen: BTreeSet::new(),
        }
    }

    /// The newest sequence selected so far.
    pub fn newest(&self) -> Option<u64> {
        self.seen.last().copied()
    }

    /// Decides for an estimate of frame `sequence`.
    pub fn offer(&mut self, sequence: u64) -> Selection {
        if let Some(newest) = self.newest() {
            let behind = newest.saturating_sub(sequence);
            if behind > 2 * self.window {
                self.seen.clear();
            } else if behind > self.window {
                return Selection::Stale;
            }
        }
        if !self.seen.insert(sequence) {
            return Selection::Duplicate;
        }
        if let Some(newest) = self.newest() {
            let oldest_kept = newest.saturating_sub(self.window);
            self.seen = self.seen.split_off(&oldest_kept);
        }
        Selection::Selected
    }

    /// Forgets everything (e.g. after a re-initialisation).
    pub fn reset(&mut self) {
        self.seen.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_arrival_wins_per_sequence() {
        let mut s = EstimateSelector::new(8);
        assert_eq!(s.offer(5), Selection::Selected);
        assert_eq!(s.offer(5), Selection::Duplicate);
        assert_eq!(s.offer(6), Selection::Selected);
        // Out of order but inside the window: still the first of its frame.
        assert_eq!(s.offer(4), Selection::Selected);
        assert_eq!(s.offer(4), Selection::Duplicate);
        assert_eq!(s.offer(6), Selection::Duplicate);
        assert_eq!(s.newest(), Some(6));
    }

    #[test]
    fn the_window_bounds_memory_and_drops_stragglers() {
        let mut s = EstimateSelector::new(4);
        for k in 0..100 {
            assert_eq!(s.offer(k), Selection::Selected);
            assert_eq!(s.offer(k), Selection::Duplicate);
        }
        assert!(s.seen.len() <= 5, "{}", s.seen.len());
        assert_eq!(s.offer(94), Selection::Stale);
        assert_eq!(s.offer(96), Selection::Duplicate);
    }

    #[test]
    fn a_restarted_source_is_followed() {
        let mut s = EstimateSelector::new(4);
        for k in 1000..1010 {
            s.offer(k);
        }
        assert_eq!(s.offer(0), Selection::Selected);
        assert_eq!(s.newest(), Some(0));
        assert_eq!(s.offer(1), Selection::Selected);
        assert_eq!(s.offer(0), Selection::Duplicate);
        s.reset();
        assert_eq!(s.offer(0), Selection::Selected);
    }
}
