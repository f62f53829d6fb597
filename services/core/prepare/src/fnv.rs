//! FNV-1a 64: a small stable hash of a source mesh's bytes, which keys the
//! on-the-fly package cache (not cryptographic; a collision only reuses a
//! cached package, and the manifest records the source path too).

/// FNV-1a 64 of `bytes`, continuing from `state` (start with [`OFFSET`]).
pub(crate) fn fnv1a64(state: u64, bytes: &[u8]) -> u64 {
    bytes.iter().fold(state, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The FNV-1a 64 offset basis.
pub(crate) const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_published_test_vectors() {
        assert_eq!(fnv1a64(OFFSET, b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(OFFSET, b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a64(OFFSET, b"foobar"), 0x8594_4171_f739_67e8);
    }
}
