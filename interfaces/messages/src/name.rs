//! Fixed-size ASCII names carried inside `#[repr(C)]` messages.

use crate::error::MessageError;
use iceoryx2::prelude::ZeroCopySend;
use serde::{Deserialize, Serialize};

/// Capacity of a [`Name`] in bytes.
pub const NAME_LEN: usize = 24;

/// Fixed-size ASCII name (instance names like `"tracker-a"`), zero-padded.
///
/// Valid names are 1 to 24 characters of `[A-Za-z0-9_.-]`; the unused tail is zero.
#[repr(C)]
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default, ZeroCopySend, Serialize, Deserialize)]
#[type_name("spacepose::Name")]
pub struct Name(pub [u8; NAME_LEN]);

impl Name {
    /// A name from a string (1 to 24 characters of `[A-Za-z0-9_.-]`).
    pub fn new(name: &str) -> Result<Name, MessageError> {
        let err = |reason| MessageError::InvalidName {
            name: name.to_string(),
            reason,
        };
        if name.is_empty() {
            return Err(err("empty"));
        }
        if name.len() > NAME_LEN {
            return Err(err("longer than 24 bytes"));
        }
        if !name.bytes().all(is_name_byte) {
            return Err(err("only A-Z, a-z, 0-9, '_', '.' and '-' are allowed"));
        }
        let mut bytes = [0u8; NAME_LEN];
        bytes[..name.len()].copy_from_slice(name.as_bytes());
        Ok(Name(bytes))
    }

    /// The name as text; `"<invalid>"` when the bytes (from the wire) are not a valid name.
    pub fn as_str(&self) -> &str {
        match self.validate() {
            Ok(()) => std::str::from_utf8(&self.0[..self.len()]).unwrap_or("<invalid>"),
            Err(_) => "<invalid>",
        }
    }

    /// True when no name is set (all zero).
    pub fn is_empty(&self) -> bool {
        self.0[0] == 0
    }

    /// Checks bytes received from the wire: name bytes, then zeros only.
    /// The all-zero (empty) name is accepted as "not set".
    pub fn validate(&self) -> Result<(), MessageError> {
        let len = self.len();
        let ok = self.0[..len].iter().copied().all(is_name_byte)
            && self.0[len..].iter().all(|&b| b == 0);
        if ok {
            Ok(())
        } else {
            Err(MessageError::InvalidName {
                name: String::from_utf8_lossy(&self.0).into_owned(),
                reason: "bytes from the wire are not a zero-padded name",
            })
        }
    }

    fn len(&self) -> usize {
        self.0.iter().position(|&b| b == 0).unwrap_or(NAME_LEN)
    }
}

fn is_name_byte(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_' || b == b'-' || b == b'.'
}

impl std::fmt::Debug for Name {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Name({:?})", self.as_str())
    }
}

impl std::fmt::Display for Name {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_are_validated() {
        let n = Name::new("tracker-a").unwrap();
        assert_eq!(n.as_str(), "tracker-a");
        assert_eq!(n.to_string(), "tracker-a");
        assert!(n.validate().is_ok());
        assert_eq!(Name::new(&"x".repeat(24)).unwrap().as_str(), "x".repeat(24));
        for bad in ["", "a b", "a/b", "é", &"x".repeat(25)] {
            assert!(Name::new(bad).is_err(), "{bad:?} accepted");
        }
        assert!(Name::default().is_empty());
        assert!(Name::default().validate().is_ok());
    }

    #[test]
    fn garbage_bytes_are_not_a_name() {
        let mut bytes = [0u8; NAME_LEN];
        bytes[0] = b'a';
        bytes[2] = b'b'; // a hole in the middle
        assert!(Name(bytes).validate().is_err());
        assert_eq!(Name(bytes).as_str(), "<invalid>");
        assert!(Name([0xff; NAME_LEN]).validate().is_err());
    }
}
