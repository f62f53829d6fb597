//! Wall-clock stamps for latency measurements across processes.

use std::time::{SystemTime, UNIX_EPOCH};

/// CLOCK_REALTIME now, in ns since the Unix epoch (0 if the clock is before 1970).
pub fn realtime_ns() -> i64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| i64::try_from(d.as_nanos()).unwrap_or(i64::MAX))
        .unwrap_or(0)
}

/// Milliseconds from `from_ns` to `to_ns` (both [`realtime_ns`] stamps);
/// `None` when either stamp is missing (0).
pub fn elapsed_ms(from_ns: i64, to_ns: i64) -> Option<f64> {
    (from_ns != 0 && to_ns != 0).then(|| (to_ns - from_ns) as f64 * 1e-6)
}
