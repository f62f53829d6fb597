//! Rate limiting of forwarded samples.

use std::time::{Duration, Instant};

/// Lets a sample through at most once per `min_interval`.
#[derive(Debug, Clone)]
pub(crate) struct Limiter {
    min_interval: Option<Duration>,
    last: Option<Instant>,
}

impl Limiter {
    pub(crate) fn new(min_interval: Option<Duration>) -> Self {
        Self {
            min_interval,
            last: None,
        }
    }

    /// True when a sample arriving at `now` may be forwarded (and records it).
    pub(crate) fn allow(&mut self, now: Instant) -> bool {
        let ok = match (self.min_interval, self.last) {
            (Some(min), Some(last)) => now.duration_since(last) >= min,
            _ => true,
        };
        if ok {
            self.last = Some(now);
        }
        ok
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_to_one_sample_per_interval() {
        let t0 = Instant::now();
        let mut l = Limiter::new(Some(Duration::from_millis(100)));
        let passed = (0..50)
            .filter(|i| l.allow(t0 + Duration::from_millis(10 * i)))
            .count();
        assert_eq!(passed, 5); // at 0, 100, 200, 300, 400 ms
        let mut unlimited = Limiter::new(None);
        assert!((0..10).all(|_| unlimited.allow(t0)));
    }
}
