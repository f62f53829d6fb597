//! The error type of the ingest library.

/// Everything that can go wrong while ingesting a frame or building the
/// ingest stage. A rejected frame is one of these values, never a panic.
///
/// A frame with no point is *not* an error (there is no `EmptyFrame`): a
/// sensor that delivered a well-formed frame (finite, ordered scan interval)
/// with nothing in it saw nothing, which is a valid observation "target not
/// seen" and is forwarded downstream (see the crate docs).
#[derive(Debug, thiserror::Error)]
pub enum IngestError {
    /// A configuration value is NaN, infinite or out of its range.
    #[error("invalid ingest config: {field} = {value} ({reason})")]
    InvalidConfig {
        /// The offending field.
        field: &'static str,
        /// Its value.
        value: f64,
        /// Why it is rejected.
        reason: &'static str,
    },

    /// The frame holds more points than the configured capacity.
    #[error("frame of {points} points exceeds the capacity of {capacity}")]
    Oversized {
        /// Points in the frame.
        points: usize,
        /// The configured capacity (`IngestConfig::max_points`).
        capacity: usize,
    },

    /// Every point of the frame has a NaN or infinite field.
    #[error("all {points} points of the frame are non-finite")]
    AllNonFinite {
        /// Points in the frame.
        points: usize,
    },

    /// The scan interval is non-finite or ends before it starts.
    #[error("invalid scan interval [{scan_start_s}, {scan_end_s}] s")]
    BadScanInterval {
        /// Scan start (s).
        scan_start_s: f64,
        /// Scan end (s).
        scan_end_s: f64,
    },
}
