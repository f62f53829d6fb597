//! Per-key rate limiting of the telemetry streams.

use std::collections::HashMap;
use std::time::{Duration, Instant};

/// Lets a key through at most once per period; `0 Hz` = always.
#[derive(Debug, Default)]
pub struct RateLimiter {
    last: HashMap<String, Instant>,
}

impl RateLimiter {
    /// An empty limiter.
    pub fn new() -> Self {
        Self::default()
    }

    /// True when `key` may be published at `now` under `max_hz`.
    pub fn allow(&mut self, key: &str, max_hz: f64, now: Instant) -> bool {
        if max_hz <= 0.0 || !max_hz.is_finite() {
            return true;
        }
        let period = Duration::from_secs_f64(1.0 / max_hz);
        match self.last.get_mut(key) {
            Some(last) if now.duration_since(*last) < period => false,
            Some(last) => {
                *last = now;
                true
            }
            None => {
                self.last.insert(key.to_string(), now);
                true
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_limited_independently() {
        let mut r = RateLimiter::new();
        let t0 = Instant::now();
        assert!(r.allow("health/a", 2.0, t0));
        assert!(!r.allow("health/a", 2.0, t0 + Duration::from_millis(400)));
        assert!(r.allow("health/b", 2.0, t0 + Duration::from_millis(400)));
        assert!(r.allow("health/a", 2.0, t0 + Duration::from_millis(500)));
        for k in 0..10 {
            assert!(r.allow("pose", 0.0, t0 + Duration::from_micros(k)));
        }
    }
}
