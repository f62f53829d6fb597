//! The vocabulary of the one-estimate-per-frame selector
//! ([`crate::selector`]): an estimate offered for a frame, how usable it
//! is, why one was chosen, and what happened to an offer.

/// How usable an estimate is for fusion (judged by the caller).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Quality {
    /// `tracking` and consistent with the prediction.
    Good,
    /// `tracking`, but too far from the filter's prediction.
    Inconsistent,
    /// `degraded` or `lost`.
    NotTracking,
}

/// One estimate offered to the selector.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate<T> {
    /// Instance that produced it (e.g. `"tracker-a"`).
    pub instance: String,
    /// Frame (cloud) sequence.
    pub sequence: u64,
    /// When the frame's cloud was published (ns, CLOCK_REALTIME); 0 when
    /// unknown (the deadline then runs from the first arrival).
    pub cloud_published_ns: i64,
    /// Usability.
    pub quality: Quality,
    /// The estimate.
    pub payload: T,
}

/// Why an estimate was chosen for its frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reason {
    /// No primary configured: the first estimate of the frame.
    FirstArrival,
    /// The primary's, on time and usable.
    Primary,
    /// The primary's, after the deadline, no standby estimate being there.
    PrimaryLate,
    /// A standby's: the primary sent nothing by the deadline.
    PrimaryMissing,
    /// A standby's: the primary's estimate was unusable.
    PrimaryUnusable(Quality),
    /// Nothing usable by the deadline (or a newer frame was decided): the
    /// best of what arrived (the primary's if any).
    Fallback,
}

/// A decision: the estimate of a frame to fuse.
#[derive(Debug, Clone, PartialEq)]
pub struct Choice<T> {
    /// The chosen estimate.
    pub candidate: Candidate<T>,
    /// Why it was chosen.
    pub reason: Reason,
}

/// What happened to an offered estimate, besides the decisions emitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Offer {
    /// It was chosen (it is in the returned decisions).
    Chosen,
    /// Kept until the primary's estimate or the deadline (decided in the
    /// same call when that deadline has already passed).
    Held,
    /// Not chosen: a better estimate of its frame was (a standby's instead
    /// of an unusable primary's).
    Superseded,
    /// Its frame was already decided (a second tracker, or a late primary).
    Duplicate,
    /// Older than the remembered window (a straggler).
    Stale,
}
