//! Errors of the bus layer.

use spacepose_messages::{CodecError, MessageError};
use thiserror::Error;

/// What went wrong on iceoryx2, zenoh or in the bridge.
#[derive(Debug, Error)]
pub enum BusError {
    /// A deployment prefix, node name or service name was refused.
    #[error("invalid name {name:?}: {reason}")]
    InvalidName {
        /// The refused name.
        name: String,
        /// Why.
        reason: String,
    },
    /// The iceoryx2 node could not be created, listed or cleaned up.
    #[error("iceoryx2 node: {0}")]
    Node(String),
    /// An iceoryx2 service could not be opened or created.
    #[error("iceoryx2 service {service:?}: {reason}")]
    Service {
        /// Service name.
        service: String,
        /// The iceoryx2 error.
        reason: String,
    },
    /// A publisher, subscriber, notifier or listener could not be created.
    #[error("iceoryx2 port on {service:?}: {reason}")]
    Port {
        /// Service name.
        service: String,
        /// The iceoryx2 error.
        reason: String,
    },
    /// Loaning or sending a sample, or notifying, failed.
    #[error("send on {service:?}: {reason}")]
    Send {
        /// Service name.
        service: String,
        /// The iceoryx2 error.
        reason: String,
    },
    /// Receiving a sample failed.
    #[error("receive on {service:?}: {reason}")]
    Receive {
        /// Service name.
        service: String,
        /// The iceoryx2 error.
        reason: String,
    },
    /// A cloud does not fit the publisher's slice capacity (it is not sent).
    #[error("cloud of {points} points exceeds the capacity of {capacity} on {service:?}")]
    CloudTooLarge {
        /// Service name.
        service: String,
        /// Points in the rejected frame.
        points: usize,
        /// Capacity of the publisher (points).
        capacity: usize,
    },
    /// The WaitSet could not be created, attached to or waited on.
    #[error("waitset: {0}")]
    WaitSet(String),
    /// zenoh configuration, session or declaration failure.
    #[error("zenoh: {0}")]
    Zenoh(String),
    /// A bridge route list is inconsistent (e.g. a topic in both directions).
    #[error("bridge configuration: {0}")]
    BridgeConfig(String),
    /// A bridge worker thread failed or died.
    #[error("bridge worker: {0}")]
    BridgeWorker(String),
    /// A payload was refused by the codec.
    #[error(transparent)]
    Codec(#[from] CodecError),
    /// A message value was invalid.
    #[error(transparent)]
    Message(#[from] MessageError),
}

impl BusError {
    pub(crate) fn service(service: &str, e: impl std::fmt::Debug) -> Self {
        BusError::Service {
            service: service.to_string(),
            reason: format!("{e:?}"),
        }
    }

    pub(crate) fn port(service: &str, e: impl std::fmt::Debug) -> Self {
        BusError::Port {
            service: service.to_string(),
            reason: format!("{e:?}"),
        }
    }

    pub(crate) fn send(service: &str, e: impl std::fmt::Debug) -> Self {
        BusError::Send {
            service: service.to_string(),
            reason: format!("{e:?}"),
        }
    }

    pub(crate) fn receive(service: &str, e: impl std::fmt::Debug) -> Self {
        BusError::Receive {
            service: service.to_string(),
            reason: format!("{e:?}"),
        }
    }

    pub(crate) fn zenoh(e: impl std::fmt::Display) -> Self {
        BusError::Zenoh(e.to_string())
    }
}
