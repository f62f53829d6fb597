//! Counters of a running bridge: forwarded, rejected and rate-limited
//! samples, and the transit time per topic taken from zenoh.

use spacepose_messages::Topic;
use std::sync::atomic::{AtomicU64, Ordering};

/// Counters of a running bridge.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BridgeStats {
    /// Samples forwarded iceoryx2 -> zenoh.
    pub forwarded_to_zenoh: u64,
    /// Samples forwarded zenoh -> iceoryx2.
    pub forwarded_from_zenoh: u64,
    /// zenoh payloads refused by the codec (garbage, wrong version or kind, oversized).
    pub rejected_wire: u64,
    /// Samples dropped by a rate limit.
    pub rate_limited: u64,
    /// Other failures (encoding a local sample, publishing, receiving).
    pub errors: u64,
}

/// Transit time of the samples a bridge took from zenoh on one topic: from
/// the sender's `published_ns` (stamped when it was published on the other
/// host's iceoryx2) to their re-publication here. Wall clock: meaningful
/// when the hosts' clocks are synchronised (one machine, or PTP/NTP);
/// samples that seem to arrive before they were sent are not counted.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LinkLatency {
    /// Samples measured.
    pub samples: u64,
    /// Mean transit time (ms).
    pub mean_ms: f64,
    /// Largest transit time (ms).
    pub max_ms: f64,
}

#[derive(Debug, Default)]
pub(crate) struct LatencySum {
    sum_us: AtomicU64,
    max_us: AtomicU64,
    samples: AtomicU64,
}

#[derive(Debug, Default)]
pub(crate) struct Counters {
    pub(crate) forwarded_to_zenoh: AtomicU64,
    pub(crate) forwarded_from_zenoh: AtomicU64,
    pub(crate) rejected_wire: AtomicU64,
    pub(crate) rate_limited: AtomicU64,
    pub(crate) errors: AtomicU64,
    /// Per topic, in the order of `Topic::ALL`.
    latency: [LatencySum; Topic::ALL.len()],
}

fn topic_index(topic: Topic) -> usize {
    Topic::ALL.iter().position(|t| *t == topic).unwrap_or(0)
}

impl Counters {
    pub(crate) fn bump(counter: &AtomicU64) {
        counter.fetch_add(1, Ordering::Relaxed);
    }

    /// Records the transit of a sample of `topic` sent at `sent_ns`
    /// (CLOCK_REALTIME) and re-published at `now_ns`.
    pub(crate) fn transit(&self, topic: Topic, sent_ns: i64, now_ns: i64) {
        if sent_ns <= 0 || now_ns < sent_ns {
            return;
        }
        let us = ((now_ns - sent_ns) / 1000) as u64;
        let l = &self.latency[topic_index(topic)];
        l.sum_us.fetch_add(us, Ordering::Relaxed);
        l.max_us.fetch_max(us, Ordering::Relaxed);
        l.samples.fetch_add(1, Ordering::Relaxed);
    }

    pub(crate) fn latency(&self, topic: Topic) -> LinkLatency {
        let l = &self.latency[topic_index(topic)];
        let samples = l.samples.load(Ordering::Relaxed);
        let sum_us = l.sum_us.load(Ordering::Relaxed);
        LinkLatency {
            samples,
            mean_ms: if samples == 0 {
                0.0
            } else {
                sum_us as f64 / samples as f64 / 1000.0
            },
            max_ms: l.max_us.load(Ordering::Relaxed) as f64 / 1000.0,
        }
    }

    pub(crate) fn snapshot(&self) -> BridgeStats {
        BridgeStats {
            forwarded_to_zenoh: self.forwarded_to_zenoh.load(Ordering::Relaxed),
            forwarded_from_zenoh: self.forwarded_from_zenoh.load(Ordering::Relaxed),
            rejected_wire: self.rejected_wire.load(Ordering::Relaxed),
            rate_limited: self.rate_limited.load(Ordering::Relaxed),
            errors: self.errors.load(Ordering::Relaxed),
        }
    }
}
