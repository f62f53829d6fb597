//! The one postcard codec for everything that crosses zenoh.
//!
//! Envelope: magic `b"SP"`, [`SCHEMA_VERSION`] (u16 little endian), the
//! message kind ([`WireMessage::KIND`], u8), then the postcard body. Decoding
//! rejects, with a [`CodecError`] value and never a panic: input larger than
//! the type's [`WireMessage::MAX_WIRE_BYTES`], truncated input, wrong magic,
//! unknown versions, wrong kind, malformed bodies, trailing bytes and
//! inconsistent content ([`WireMessage::validate`]).

use crate::SCHEMA_VERSION;
pub use crate::error::CodecError;
use serde::Serialize;
use serde::de::DeserializeOwned;

/// First two bytes of every encoded message.
pub const MAGIC: [u8; 2] = *b"SP";
/// Envelope length: magic (2) + version (2) + kind (1).
pub const ENVELOPE_LEN: usize = 5;

/// A message that travels in the postcard codec.
pub trait WireMessage: Serialize + DeserializeOwned {
    /// Message kind written in the envelope (unique per type).
    const KIND: u8;
    /// Largest accepted encoded size, envelope included (bytes).
    const MAX_WIRE_BYTES: usize;

    /// The `schema` field of the message (must equal [`SCHEMA_VERSION`]).
    fn schema(&self) -> u16;

    /// Checks the content after decoding (enumeration codes, names, counts).
    fn validate(&self) -> Result<(), CodecError> {
        Ok(())
    }

    /// Stamps the send time (CLOCK_REALTIME, ns) where the message has one.
    fn set_published_ns(&mut self, _ns: i64) {}
}

/// Upper bound of the encoded size of a fixed-size `#[repr(C)]` message:
/// postcard varints take at most 10 bytes for a u64/i64, 5 for a u32 and 3
/// for a u16, never more than twice the in-memory size, plus the envelope.
pub const fn fixed_max_wire_bytes<T>() -> usize {
    2 * std::mem::size_of::<T>() + ENVELOPE_LEN + 16
}

/// Encodes a message with the envelope.
pub fn encode<T: WireMessage>(msg: &T) -> Result<Vec<u8>, CodecError> {
    msg.validate()?;
    let mut out = Vec::with_capacity(64);
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&SCHEMA_VERSION.to_le_bytes());
    out.push(T::KIND);
    let out = postcard::to_extend(msg, out).map_err(|e| CodecError::Encode(e.to_string()))?;
    if out.len() > T::MAX_WIRE_BYTES {
        return Err(CodecError::Oversized {
            len: out.len(),
            max: T::MAX_WIRE_BYTES,
        });
    }
    Ok(out)
}

/// Decodes a message, checking the envelope, the size and the content.
pub fn decode<T: WireMessage>(bytes: &[u8]) -> Result<T, CodecError> {
    let len = bytes.len();
    if len > T::MAX_WIRE_BYTES {
        return Err(CodecError::Oversized {
            len,
            max: T::MAX_WIRE_BYTES,
        });
    }
    if len < ENVELOPE_LEN {
        return Err(CodecError::Truncated { len });
    }
    let magic = [bytes[0], bytes[1]];
    if magic != MAGIC {
        return Err(CodecError::BadMagic { found: magic });
    }
    let version = u16::from_le_bytes([bytes[2], bytes[3]]);
    if version != SCHEMA_VERSION {
        return Err(CodecError::UnknownVersion {
            found: version,
            expected: SCHEMA_VERSION,
        });
    }
    if bytes[4] != T::KIND {
        return Err(CodecError::WrongKind {
            found: bytes[4],
            expected: T::KIND,
        });
    }
    let (msg, rest) =
        postcard::take_from_bytes::<T>(&bytes[ENVELOPE_LEN..]).map_err(|e| match e {
            postcard::Error::DeserializeUnexpectedEnd => CodecError::Truncated { len },
            other => CodecError::Malformed(other.to_string()),
        })?;
    if !rest.is_empty() {
        return Err(CodecError::TrailingBytes { extra: rest.len() });
    }
    if msg.schema() != SCHEMA_VERSION {
        return Err(CodecError::Invalid(format!(
            "schema field {} differs from the envelope version {SCHEMA_VERSION}",
            msg.schema()
        )));
    }
    msg.validate()?;
    Ok(msg)
}

/// The kind byte of an encoded message, if the envelope is readable
/// (lets a receiver dispatch before decoding).
pub fn peek_kind(bytes: &[u8]) -> Option<u8> {
    (bytes.len() >= ENVELOPE_LEN && bytes[..2] == MAGIC).then(|| bytes[4])
}

/// Maps a code-range check to a codec error.
pub(crate) fn check_code(what: &str, code: u8, max: u8) -> Result<(), CodecError> {
    if code > max {
        Err(CodecError::Invalid(format!("unknown {what} code {code}")))
    } else {
        Ok(())
    }
}

/// Maps an invalid name to a codec error.
pub(crate) fn check_name(field: &str, name: &crate::Name) -> Result<(), CodecError> {
    name.validate()
        .map_err(|e| CodecError::Invalid(format!("{field}: {e}")))
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod fuzz_tests;
