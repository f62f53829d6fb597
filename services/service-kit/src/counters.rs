//! Counters every service reports in its health message.

/// Counters of one service since it started (frames unless said otherwise).
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct Counters {
    /// Frames (or messages) received.
    pub frames_in: u64,
    /// Frames (or messages) published.
    pub frames_out: u64,
    /// Frames that held NaN or infinite points.
    pub rejected_non_finite: u64,
    /// Empty frames rejected.
    pub rejected_empty: u64,
    /// Frames above capacity rejected.
    pub rejected_oversized: u64,
    /// Wire payloads rejected by the codec.
    pub rejected_wire: u64,
    /// Other errors (processing, bus, files).
    pub errors: u64,
    /// Sequence of the last frame processed.
    pub last_frame: u64,
}
