//! The statistics file (`stats_file`): the routes' counters and the link
//! latencies as JSON, rewritten every `stats_period_s` and at exit.

use spacepose_runtime::LinkStatus;
use std::path::Path;

/// When the statistics are next due, on the node's clock (ns).
#[derive(Debug)]
pub struct Schedule {
    period_ns: i64,
    next_ns: Option<i64>,
}

impl Schedule {
    /// Every `period_s` seconds (> 0), the first period starting at the
    /// first [`Schedule::due`].
    pub fn every(period_s: f64) -> Self {
        Schedule {
            period_ns: ((period_s * 1e9).round() as i64).max(1),
            next_ns: None,
        }
    }

    /// True when a period ended at `now_ns`; the next one starts then. A
    /// clock stepped back before the current period's start also ends it,
    /// so the file is never left stale until the clock catches up.
    pub fn due(&mut self, now_ns: i64) -> bool {
        let due = match self.next_ns {
            None => false,
            Some(next) => now_ns >= next || now_ns < next.saturating_sub(self.period_ns),
        };
        if due || self.next_ns.is_none() {
            self.next_ns = Some(now_ns.saturating_add(self.period_ns));
        }
        due
    }

    /// When the current period ends; `None` before the first [`Schedule::due`].
    pub fn next_ns(&self) -> Option<i64> {
        self.next_ns
    }
}

/// The statistics of `link`: forwarded, refused, rate-limited and failed
/// samples, the transit times of the inbound routes, and the routes.
pub fn stats_json(link: &LinkStatus) -> serde_json::Value {
    let s = &link.stats;
    let latency: serde_json::Map<String, serde_json::Value> = link
        .latency
        .iter()
        .map(|(topic, l)| {
            let v = serde_json::json!({ "samples": l.samples, "mean_ms": l.mean_ms, "max_ms": l.max_ms });
            (topic.as_str().to_string(), v)
        })
        .collect();
    let routes: Vec<String> = link
        .routes
        .iter()
        .map(|r| format!("{} {:?}", r.topic.as_str(), r.direction))
        .collect();
    serde_json::json!({
        "forwarded_to_zenoh": s.forwarded_to_zenoh,
        "forwarded_from_zenoh": s.forwarded_from_zenoh,
        "rejected_wire": s.rejected_wire,
        "rate_limited": s.rate_limited,
        "errors": s.errors,
        "latency_from_zenoh": latency,
        "routes": routes,
    })
}

/// Writes the statistics of `link` to `path` through a temporary file
/// renamed over it, so a reader never sees half a file; a failure is logged.
pub fn write_stats(path: &Path, link: &LinkStatus) {
    let tmp = path.with_extension("tmp");
    let json = stats_json(link).to_string();
    let written = std::fs::write(&tmp, json).and_then(|()| std::fs::rename(&tmp, path));
    if let Err(e) = written {
        tracing::warn!(path = %path.display(), "writing the bridge statistics: {e}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spacepose_bus::{LinkLatency, Route};
    use spacepose_messages::Topic;

    const S: i64 = 1_000_000_000;

    #[test]
    fn the_schedule_waits_a_period_first_and_survives_a_clock_step() {
        let mut s = Schedule::every(2.0);
        let t0 = 1_700_000_000 * S;
        assert_eq!(s.next_ns(), None);
        assert!(!s.due(t0));
        assert_eq!(s.next_ns(), Some(t0 + 2 * S));
        assert!(!s.due(t0 + S));
        assert!(s.due(t0 + 2 * S));
        assert!(!s.due(t0 + 3 * S));
        // One hour back: due at once, then every period from there.
        let back = t0 - 3600 * S;
        assert!(s.due(back));
        assert!(!s.due(back + S));
        assert!(s.due(back + 2 * S));
    }

    #[test]
    fn the_file_holds_the_counters_latencies_and_routes() {
        let mut link = LinkStatus {
            routes: vec![
                Route::from_zenoh(Topic::Cloud),
                Route::to_zenoh(Topic::Pose),
            ],
            latency: vec![(
                Topic::Cloud,
                LinkLatency {
                    samples: 3,
                    mean_ms: 1.5,
                    max_ms: 2.5,
                },
            )],
            running: true,
            ..LinkStatus::default()
        };
        link.stats.forwarded_from_zenoh = 3;
        link.stats.forwarded_to_zenoh = 4;
        link.stats.rate_limited = 1;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bridge-b.stats.json");
        write_stats(&path, &link);
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        assert_eq!(
            (
                v["forwarded_from_zenoh"].as_u64(),
                v["forwarded_to_zenoh"].as_u64()
            ),
            (Some(3), Some(4))
        );
        assert_eq!(
            (
                v["rejected_wire"].as_u64(),
                v["rate_limited"].as_u64(),
                v["errors"].as_u64()
            ),
            (Some(0), Some(1), Some(0))
        );
        assert_eq!(v["latency_from_zenoh"]["cloud"]["samples"], 3);
        assert_eq!(v["latency_from_zenoh"]["cloud"]["max_ms"], 2.5);
        assert_eq!(
            v["routes"],
            serde_json::json!(["cloud FromZenoh", "pose ToZenoh"])
        );
        assert!(!dir.path().join("bridge-b.stats.tmp").exists());
        // An unwritable place is logged, not fatal.
        write_stats(&dir.path().join("absent/dir/stats.json"), &link);
    }
}
