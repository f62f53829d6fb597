//! Minimal `.npy` (NumPy format version 1.0) for little-endian `float32`
//! arrays: a streaming writer (header first, rows appended) and a reader.
//!
//! Layout: magic `\x93NUMPY`, version `1 0`, a little-endian `u16` header
//! length, then an ASCII dict `{'descr': '<f4', 'fortran_order': False,
//! 'shape': (...), }` padded with spaces and a final `\n` so that the data
//! starts at a multiple of 64 bytes, then the raw C-order data.

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use crate::error::{CnnError, io_err};

const MAGIC: &[u8] = b"\x93NUMPY";

/// The header bytes of a C-order `<f4` array of `shape`.
pub fn header(shape: &[usize]) -> Vec<u8> {
    let dims = match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut dict = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {dims}, }}");
    let unpadded = MAGIC.len() + 2 + 2 + dict.len() + 1;
    dict.push_str(&" ".repeat((64 - unpadded % 64) % 64));
    dict.push('\n');
    let mut out = Vec::with_capacity(unpadded + 64);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    // The dict is a few hundred bytes at most: it fits a u16.
    out.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    out
}

/// Streams a `float32` array of a known shape to disk.
#[derive(Debug)]
pub struct NpyWriter {
    path: PathBuf,
    file: BufWriter<File>,
    expected: usize,
    written: usize,
}

impl NpyWriter {
    /// Creates `path` and writes the header of an array of `shape`.
    ///
    /// # Errors
    /// [`CnnError::Io`] if the file cannot be created or written.
    pub fn create(path: &Path, shape: &[usize]) -> Result<Self, CnnError> {
        let mut file = BufWriter::with_capacity(1 << 20, File::create(path).map_err(io_err(path))?);
        file.write_all(&header(shape)).map_err(io_err(path))?;
        Ok(NpyWriter {
            path: path.to_path_buf(),
            file,
            expected: shape.iter().product(),
            written: 0,
        })
    }

    /// Appends values (C order), little-endian.
    ///
    /// # Errors
    /// [`CnnError::Io`] on a write error; [`CnnError::Npy`] if more values
    /// than the shape holds are written.
    pub fn write(&mut self, values: &[f32]) -> Result<(), CnnError> {
        if self.written + values.len() > self.expected {
            return Err(CnnError::Npy {
                path: self.path.clone(),
                reason: format!("more than the {} values of the shape", self.expected),
            });
        }
        let mut bytes = Vec::with_capacity(4 * values.len());
        for v in values {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        self.file.write_all(&bytes).map_err(io_err(&self.path))?;
        self.written += values.len();
        Ok(())
    }

    /// Flushes, checking that exactly the shape's number of values was written.
    ///
    /// # Errors
    /// [`CnnError::Npy`] for a short array, [`CnnError::Io`] on a flush error.
    pub fn finish(mut self) -> Result<(), CnnError> {
        if self.written != self.expected {
            return Err(CnnError::Npy {
                path: self.path.clone(),
                reason: format!("{} of {} values written", self.written, self.expected),
            });
        }
        self.file.flush().map_err(io_err(&self.path))
    }
}

/// Writes a whole `float32` array.
///
/// # Errors
/// As [`NpyWriter`].
pub fn write_f32(path: &Path, shape: &[usize], values: &[f32]) -> Result<(), CnnError> {
    let mut w = NpyWriter::create(path, shape)?;
    w.write(values)?;
    w.finish()
}

/// Reads a C-order little-endian `float32` `.npy` file: (shape, values).
///
/// # Errors
/// [`CnnError::Io`] on read errors; [`CnnError::Npy`] for a bad magic,
/// version, dtype, order, shape, or a data size that does not match the shape.
pub fn read_f32(path: &Path) -> Result<(Vec<usize>, Vec<f32>), CnnError> {
    let bad = |reason: &str| CnnError::Npy {
        path: path.to_path_buf(),
        reason: reason.to_string(),
    };
    let mut r = BufReader::new(File::open(path).map_err(io_err(path))?);
    let mut pre = [0u8; 10];
    r.read_exact(&mut pre)
        .map_err(|_| bad("truncated preamble"))?;
    if &pre[..6] != MAGIC {
        return Err(bad("bad magic"));
    }
    if pre[6] != 1 {
        return Err(bad("only format version 1.0 is supported"));
    }
    let len = usize::from(u16::from_le_bytes([pre[8], pre[9]]));
    let mut dict = vec![0u8; len];
    r.read_exact(&mut dict)
        .map_err(|_| bad("truncated header"))?;
    let dict = String::from_utf8(dict).map_err(|_| bad("header is not text"))?;
    if !dict.contains("'descr': '<f4'") {
        return Err(bad("dtype is not little-endian float32"));
    }
    if !dict.contains("'fortran_order': False") {
        return Err(bad("Fortran order is not supported"));
    }
    let shape = parse_shape(&dict).ok_or_else(|| bad("unreadable shape"))?;
    let mut data = Vec::new();
    r.read_to_end(&mut data).map_err(io_err(path))?;
    let count: usize = shape.iter().product();
    if data.len() != 4 * count {
        return Err(bad(&format!(
            "{} data bytes for {} values",
            data.len(),
            count
        )));
    }
    let values = data
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    Ok((shape, values))
}

fn parse_shape(dict: &str) -> Option<Vec<usize>> {
    let start = dict.find("'shape': (")? + "'shape': (".len();
    let end = start + dict[start..].find(')')?;
    dict[start..end]
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().ok())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_is_valid_npy_v1() {
        for shape in [vec![7], vec![3, 4], vec![10, 64, 64], vec![0, 618]] {
            let h = header(&shape);
            assert_eq!(&h[..6], MAGIC);
            assert_eq!(&h[6..8], &[1, 0]);
            let len = usize::from(u16::from_le_bytes([h[8], h[9]]));
            assert_eq!(h.len(), 10 + len);
            assert_eq!(h.len() % 64, 0, "data must start 64-byte aligned");
            assert_eq!(*h.last().unwrap(), b'\n');
            let text = std::str::from_utf8(&h[10..]).unwrap();
            assert!(text.starts_with("{'descr': '<f4', 'fortran_order': False, 'shape': ("));
            assert_eq!(parse_shape(text).unwrap(), shape);
        }
        assert!(
            header(&[7]).windows(4).any(|w| w == b"(7,)"),
            "1-D shape is a tuple"
        );
    }

    #[test]
    fn written_file_reads_back_and_has_a_valid_header() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.npy");
        let values: Vec<f32> = (0..24).map(|i| i as f32 * 0.5 - 3.0).collect();
        let mut w = NpyWriter::create(&path, &[2, 3, 4]).unwrap();
        w.write(&values[..10]).unwrap();
        w.write(&values[10..]).unwrap();
        w.finish().unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
        assert_eq!(bytes.len(), 128 + 24 * 4);
        let (shape, back) = read_f32(&path).unwrap();
        assert_eq!(shape, vec![2, 3, 4]);
        assert_eq!(back, values);
    }

    #[test]
    fn short_or_long_arrays_and_corrupt_files_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("b.npy");
        let mut w = NpyWriter::create(&path, &[4]).unwrap();
        w.write(&[1.0, 2.0]).unwrap();
        assert!(w.write(&[1.0, 2.0, 3.0]).is_err());
        assert!(matches!(w.finish(), Err(CnnError::Npy { .. })));
        std::fs::write(&path, b"not a numpy file at all").unwrap();
        assert!(matches!(read_f32(&path), Err(CnnError::Npy { .. })));
        write_f32(&path, &[2], &[1.0, 2.0]).unwrap();
        let mut bytes = std::fs::read(&path).unwrap();
        bytes.pop();
        std::fs::write(&path, bytes).unwrap();
        assert!(matches!(read_f32(&path), Err(CnnError::Npy { .. })));
    }
}
