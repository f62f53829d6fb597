//! Per-key rate limiting of the telemetry streams.

use std::collections::HashMap;

/// Lets a key through at most once per period; `0 Hz` = always.
///
/// Times are the node's clock (`Ctx::now_ns`, CLOCK_REALTIME in ns): a
/// clock stepped back lets the next sample through and restarts the period
/// from it, so a stream is never silenced until the clock catches up.
#[derive(Debug, Default)]
pub struct RateLimiter {
    last: HashMap<String, i64>,
}

impl RateLimiter {
    /// An empty limiter.
    pub fn new() -> Self {
        Self::default()
    }

    /// True when `key` may be published at `now_ns` under `max_hz`.
    pub fn allow(&mut self, key: &str, max_hz: f64, now_ns: i64) -> bool {
        if max_hz <= 0.0 || !max_hz.is_finite() {
            return true;
        }
        // Saturates for rates below 1e-9 Hz: once, then never again.
        let period_ns = (1e9 / max_hz).round() as i64;
        match self.last.get_mut(key) {
            Some(last) if (0..period_ns).contains(&now_ns.saturating_sub(*last)) => false,
            Some(last) => {
                *last = now_ns;
                true
            }
            None => {
                self.last.insert(key.to_string(), now_ns);
                true
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: i64 = 1_000_000;

    #[test]
    fn keys_are_limited_independently() {
        let mut r = RateLimiter::new();
        let t0 = 1_700_000_000_000 * MS;
        assert!(r.allow("health/a", 2.0, t0));
        assert!(!r.allow("health/a", 2.0, t0 + 400 * MS));
        assert!(r.allow("health/b", 2.0, t0 + 400 * MS));
        assert!(r.allow("health/a", 2.0, t0 + 500 * MS));
        for k in 0..10 {
            assert!(r.allow("pose", 0.0, t0 + k * 1_000));
        }
    }

    #[test]
    fn a_clock_stepped_back_does_not_silence_a_stream() {
        let mut r = RateLimiter::new();
        let t0 = 1_700_000_000_000 * MS;
        assert!(r.allow("filter", 10.0, t0));
        assert!(!r.allow("filter", 10.0, t0 + 99 * MS));
        // One hour back: through at once, and limited from there.
        let back = t0 - 3_600_000 * MS;
        assert!(r.allow("filter", 10.0, back));
        assert!(!r.allow("filter", 10.0, back + 50 * MS));
        assert!(r.allow("filter", 10.0, back + 100 * MS));
        // A rate so low that its period overflows: once only.
        assert!(r.allow("truth", 1e-300, t0));
        assert!(!r.allow("truth", 1e-300, i64::MAX));
    }
}
