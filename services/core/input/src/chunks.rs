//! A check of MCAP chunk sizes before anything is decompressed.
//!
//! The `mcap` crate allocates a chunk's declared `uncompressed_size` before
//! decompressing it, so one corrupt size field aborts the process on an
//! impossible allocation. Every chunk header is therefore checked first:
//! an uncompressed chunk must declare its own length, a compressed one at
//! most [`MAX_CHUNK_RATIO`] times its compressed length (lidar data
//! compresses 2–5×) and at most [`MAX_CHUNK_BYTES`].

use crate::error::InputError;
use mcap::read::{LinearReader, Options};
use mcap::records::Record;
use std::path::Path;

/// Largest accepted ratio of a chunk's uncompressed to compressed size.
pub const MAX_CHUNK_RATIO: u64 = 256;

/// Largest accepted uncompressed chunk (bytes).
pub const MAX_CHUNK_BYTES: u64 = 1 << 30;

/// Checks every chunk header of `buf` (up to the first unreadable record,
/// which the message reader reports in place).
///
/// # Errors
/// [`InputError::Mcap`] naming the first chunk with an impossible size.
pub(crate) fn check_chunk_sizes(path: &Path, buf: &[u8]) -> Result<(), InputError> {
    let Ok(reader) = LinearReader::new_with_options(buf, Options::IgnoreEndMagic.into()) else {
        return Ok(());
    };
    for (k, record) in reader.enumerate() {
        let Ok(record) = record else { break };
        let Record::Chunk { header, data } = record else {
            continue;
        };
        let compressed = data.len() as u64;
        let plausible = if header.compression.is_empty() {
            header.uncompressed_size == compressed
        } else {
            header.uncompressed_size <= compressed.saturating_mul(MAX_CHUNK_RATIO).max(4096)
                && header.uncompressed_size <= MAX_CHUNK_BYTES
        };
        if !plausible {
            return Err(InputError::Mcap {
                path: path.to_owned(),
                message: format!(
                    "corrupt chunk (record {k}): {} bytes uncompressed ({:?}) from {compressed} bytes",
                    header.uncompressed_size, header.compression
                ),
            });
        }
    }
    Ok(())
}
