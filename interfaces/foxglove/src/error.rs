//! Errors of the conversions, of the recorder and of the live view.

/// What went wrong while recording.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The MCAP file could not be created, written or closed.
    #[error("MCAP file {path}: {source}")]
    File {
        /// The recording's path.
        path: String,
        /// The SDK's error.
        #[source]
        source: foxglove::FoxgloveError,
    },
    /// A channel could not be declared.
    #[error("channel {topic}: {source}")]
    Channel {
        /// The channel's topic.
        topic: String,
        /// The SDK's error.
        #[source]
        source: foxglove::FoxgloveError,
    },
    /// The live view's WebSocket server could not start.
    #[error("live view on {addr}: {source}")]
    Server {
        /// The address it was to listen on.
        addr: String,
        /// The SDK's error.
        #[source]
        source: foxglove::FoxgloveError,
    },
    /// A message held a code or a rotation the suite does not know.
    #[error("message refused: {0}")]
    Message(#[from] spacepose_messages::MessageError),
    /// A record could not be written as JSON.
    #[error("JSON: {0}")]
    Json(#[from] serde_json::Error),
}
