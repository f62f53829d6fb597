//! The eval's one far-off bound: frames, acquisitions and tables use it.

/// A frame whose error exceeds these has lost the target in truth, whatever
/// the tracker reports.
pub const DIVERGED_DEG: f64 = 10.0;
/// See [`DIVERGED_DEG`] (m).
pub const DIVERGED_M: f64 = 0.5;
