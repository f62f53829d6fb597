//! Why a control message (command, acquisition, filter state) was refused.

use spacepose_messages::MessageError;
use spacepose_tracker::TrackError;
use thiserror::Error;

/// A control message the tracker node could not apply: counted in
/// `rejected_wire` and logged; the track goes on unchanged.
#[derive(Debug, Error)]
pub enum ControlError {
    /// The message does not hold what it claims (bad quaternion, unknown
    /// code, non-finite value); `what` names it.
    #[error("invalid {what} message: {source}")]
    Invalid {
        /// Which message was refused.
        what: &'static str,
        /// Why.
        #[source]
        source: MessageError,
    },
    /// The tracker could not do what it asked (a mode whose model cannot
    /// be built, a state it cannot restore).
    #[error(transparent)]
    Track(#[from] TrackError),
}

/// `MessageError` of the message `what` as a [`ControlError`].
pub(crate) fn invalid(what: &'static str) -> impl Fn(MessageError) -> ControlError {
    move |source| ControlError::Invalid { what, source }
}
