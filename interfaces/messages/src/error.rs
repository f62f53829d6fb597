//! Errors of the message crate: invalid values and codec failures.

use thiserror::Error;

/// A value that cannot be put in (or taken out of) a message.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MessageError {
    /// An instance/service name is empty, too long or not `[a-z0-9_-]` ASCII.
    #[error("invalid name {name:?}: {reason}")]
    InvalidName {
        /// The rejected name.
        name: String,
        /// Why it was rejected.
        reason: &'static str,
    },
    /// A deployment prefix is not `[a-z0-9_-]{{1,32}}`.
    #[error("invalid deployment prefix {prefix:?}: {reason}")]
    InvalidPrefix {
        /// The rejected prefix.
        prefix: String,
        /// Why it was rejected.
        reason: &'static str,
    },
    /// A pose carried NaN or infinite numbers.
    #[error("non-finite pose in message")]
    NonFinitePose,
    /// A quaternion is too far from unit norm to be a rotation.
    #[error("quaternion norm {norm} is not close to 1")]
    InvalidQuaternion {
        /// Norm of the received quaternion.
        norm: f64,
    },
    /// A message whose values cannot be what they claim (a time or a
    /// covariance that is not finite, ...).
    #[error("invalid {what}: {reason}")]
    InvalidMessage {
        /// Which message.
        what: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// An enumeration stored as `u8` has a value that names no variant.
    #[error("unknown {what} code {code}")]
    UnknownCode {
        /// Which enumeration.
        what: &'static str,
        /// The received value.
        code: u8,
    },
}

/// Why bytes could not be decoded into a message (or a message encoded).
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum CodecError {
    /// Shorter than the envelope, or the postcard body ended early.
    #[error("truncated input ({len} bytes)")]
    Truncated {
        /// Number of bytes received.
        len: usize,
    },
    /// The first two bytes are not the `SP` magic.
    #[error("bad magic {found:02x?}")]
    BadMagic {
        /// The two bytes found.
        found: [u8; 2],
    },
    /// The schema version in the envelope is not one this build understands.
    #[error("unknown schema version {found} (this build speaks {expected})")]
    UnknownVersion {
        /// Version in the envelope.
        found: u16,
        /// Version this build speaks.
        expected: u16,
    },
    /// The message kind in the envelope is not the requested type.
    #[error("wrong message kind {found} (expected {expected})")]
    WrongKind {
        /// Kind in the envelope.
        found: u8,
        /// Kind of the requested type.
        expected: u8,
    },
    /// Input (or an encoded message) is larger than the type's maximum wire size.
    #[error("oversized message: {len} bytes > {max}")]
    Oversized {
        /// Size of the input.
        len: usize,
        /// Largest size accepted for the type.
        max: usize,
    },
    /// Bytes were left after the message body.
    #[error("{extra} trailing bytes after the message")]
    TrailingBytes {
        /// Number of bytes left over.
        extra: usize,
    },
    /// The body is not a valid postcard encoding of the type.
    #[error("malformed body: {0}")]
    Malformed(String),
    /// The body decoded but its content is inconsistent (schema field, counts).
    #[error("invalid content: {0}")]
    Invalid(String),
    /// Postcard failed to serialise the message.
    #[error("encoding failed: {0}")]
    Encode(String),
}
