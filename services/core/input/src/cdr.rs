//! A reader of plain little-endian CDR (the ROS 2 serialisation): a 4-byte
//! encapsulation header, then fields aligned to their size, relative to the
//! end of the header.

use crate::error::CloudError;

/// Encapsulation identifiers (first two bytes, big-endian).
const CDR_BE: u16 = 0x0000;
const CDR_LE: u16 = 0x0001;
const PL_CDR_BE: u16 = 0x0002;
const CDR2_BE: u16 = 0x0006;
const CDR2_LE: u16 = 0x0007;

/// Reads fields in order from one CDR message.
#[derive(Debug)]
pub(crate) struct CdrReader<'a> {
    body: &'a [u8],
    pos: usize,
}

impl<'a> CdrReader<'a> {
    /// Checks the encapsulation header: plain CDR little-endian (`0x0001`),
    /// or plain XCDR2 little-endian (`0x0007`, identical for messages
    /// without 8-byte primitives, such as PointCloud2).
    ///
    /// # Errors
    /// [`CloudError::BigEndian`], [`CloudError::Encapsulation`] or
    /// [`CloudError::Truncated`].
    pub fn new(message: &'a [u8]) -> Result<Self, CloudError> {
        let header = message
            .get(..4)
            .ok_or(CloudError::Truncated("the CDR encapsulation header"))?;
        match u16::from_be_bytes([header[0], header[1]]) {
            CDR_LE | CDR2_LE => Ok(CdrReader {
                body: &message[4..],
                pos: 0,
            }),
            CDR_BE | PL_CDR_BE | CDR2_BE => Err(CloudError::BigEndian("CDR encapsulation")),
            other => Err(CloudError::Encapsulation(other)),
        }
    }

    /// The next `n` bytes, after aligning to `align`.
    fn take(&mut self, n: usize, align: usize, what: &'static str) -> Result<&'a [u8], CloudError> {
        let start = self.pos.next_multiple_of(align);
        let bytes = start
            .checked_add(n)
            .and_then(|end| self.body.get(start..end))
            .ok_or(CloudError::Truncated(what))?;
        self.pos = start + n;
        Ok(bytes)
    }

    /// A `uint8` (or `bool`).
    pub fn u8(&mut self, what: &'static str) -> Result<u8, CloudError> {
        Ok(self.take(1, 1, what)?[0])
    }

    /// A `uint32`.
    pub fn u32(&mut self, what: &'static str) -> Result<u32, CloudError> {
        let b = self.take(4, 4, what)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    /// An `int32`.
    pub fn i32(&mut self, what: &'static str) -> Result<i32, CloudError> {
        let b = self.take(4, 4, what)?;
        Ok(i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    /// A `string`: length (with the terminating NUL), bytes, NUL.
    pub fn string(&mut self, what: &'static str) -> Result<String, CloudError> {
        let n = self.u32(what)? as usize;
        let bytes = self.take(n, 1, what)?;
        let text = bytes.strip_suffix(&[0]).unwrap_or(bytes);
        Ok(String::from_utf8_lossy(text).into_owned())
    }

    /// A `uint8[]` sequence, borrowed.
    pub fn bytes(&mut self, what: &'static str) -> Result<&'a [u8], CloudError> {
        let n = self.u32(what)? as usize;
        self.take(n, 1, what)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_aligned_after_the_header() {
        // header, u8 = 7, (3 pad), u32 = 9, string "ab"
        let mut m = vec![0, 1, 0, 0, 7, 0, 0, 0];
        m.extend_from_slice(&9u32.to_le_bytes());
        m.extend_from_slice(&3u32.to_le_bytes());
        m.extend_from_slice(b"ab\0");
        let mut r = CdrReader::new(&m).unwrap();
        assert_eq!(r.u8("a").unwrap(), 7);
        assert_eq!(r.u32("b").unwrap(), 9);
        assert_eq!(r.string("c").unwrap(), "ab");
        assert_eq!(r.u8("d"), Err(CloudError::Truncated("d")));
    }

    #[test]
    fn big_endian_and_other_encapsulations_are_refused() {
        assert_eq!(
            CdrReader::new(&[0, 0, 0, 0]).unwrap_err(),
            CloudError::BigEndian("CDR encapsulation")
        );
        assert_eq!(
            CdrReader::new(&[0, 3, 0, 0]).unwrap_err(),
            CloudError::Encapsulation(3)
        );
        assert!(matches!(
            CdrReader::new(&[0, 1]),
            Err(CloudError::Truncated(_))
        ));
    }

    #[test]
    fn a_huge_length_is_truncation_not_a_panic() {
        let mut m = vec![0, 1, 0, 0];
        m.extend_from_slice(&u32::MAX.to_le_bytes());
        let mut r = CdrReader::new(&m).unwrap();
        assert!(matches!(
            r.bytes("data"),
            Err(CloudError::Truncated("data"))
        ));
    }
}
