//! Times of a recording: every message is logged at a sensor-clock time.
//!
//! The log time of a message is the time of validity of the frame it
//! belongs to, on the sensor clock: a cloud's scan end, a pose's, a truth's
//! or a filter state's `t_s`, an acquisition's `t_s`. Heartbeats carry no
//! sensor time: they are logged at the newest sensor time recorded so far.
//! So replaying a recording orders the messages as the sensor produced the
//! frames, whatever the scheduling of the processes that wrote them. The
//! MCAP log time is in ns; sensor clocks that start at 0 s give times near
//! the Unix epoch, which Foxglove shows as they are.

use foxglove::messages::Timestamp;

/// The log time (ns) of sensor time `t_s` (s): rounded to the ns,
/// saturating at 0 for negative or NaN times and at `u64::MAX`.
pub fn log_time_ns(t_s: f64) -> u64 {
    // `as` saturates and maps NaN to 0.
    (t_s * 1e9).round() as u64
}

/// The Foxglove timestamp of sensor time `t_s` (s), equal to
/// [`log_time_ns`] (saturating at the range of a `Timestamp`).
pub fn timestamp(t_s: f64) -> Timestamp {
    let ns = log_time_ns(t_s);
    let sec = u32::try_from(ns / 1_000_000_000).unwrap_or(u32::MAX);
    Timestamp::new(sec, (ns % 1_000_000_000) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sensor_seconds_become_nanoseconds() {
        assert_eq!(log_time_ns(0.0), 0);
        assert_eq!(log_time_ns(1.25), 1_250_000_000);
        assert_eq!(log_time_ns(0.1), 100_000_000);
        assert_eq!(log_time_ns(-3.0), 0);
        assert_eq!(log_time_ns(f64::NAN), 0);
        let t = timestamp(12.000_000_5);
        assert_eq!((t.sec(), t.nsec()), (12, 500));
        assert_eq!(t.total_nanos(), log_time_ns(12.000_000_5));
    }
}
