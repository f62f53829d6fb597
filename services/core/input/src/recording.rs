//! [`open`]: any supported recording behind one type.

use crate::error::InputError;
use crate::frame::InputFrame;
use crate::mcap_source::{McapSource, bag_files};
use crate::options::InputOptions;
use crate::pcd_dir::PcdDir;
use std::path::Path;

/// The first bytes of an MCAP file.
const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// An opened recording: a frame directory, an MCAP file or a ROS 2 bag.
#[derive(Debug)]
pub enum Recording {
    /// `frame_NNNNNN.pcd` / `.ply` files (and `truth.csv`).
    PcdDir(PcdDir),
    /// An MCAP file or a ROS 2 bag.
    Mcap(McapSource),
}

/// Opens `path`, whatever it is: a directory with `metadata.yaml` is a ROS 2
/// bag, another directory a frame directory, a file starting with the MCAP
/// magic (or named `.mcap`) an MCAP file.
///
/// # Errors
/// [`InputError::Options`] for invalid options, [`InputError::UnknownFormat`]
/// for anything else, and the errors of the readers ([`PcdDir::open`],
/// [`McapSource::open`]).
pub fn open(path: &Path, options: &InputOptions) -> Result<Recording, InputError> {
    options.validate().map_err(InputError::Options)?;
    if path.is_dir() {
        if path.join("metadata.yaml").is_file() {
            let files = bag_files(path)?;
            return Ok(Recording::Mcap(McapSource::open(path, &files, options)?));
        }
        return Ok(Recording::PcdDir(PcdDir::open(path, options)?));
    }
    if is_mcap(path)? {
        return Ok(Recording::Mcap(McapSource::open(
            path,
            &[path.to_owned()],
            options,
        )?));
    }
    Err(InputError::UnknownFormat(path.to_owned()))
}

fn is_mcap(path: &Path) -> Result<bool, InputError> {
    use std::io::Read;
    let io = |source| InputError::Io {
        path: path.to_owned(),
        source,
    };
    let mut magic = [0u8; 8];
    let mut file = std::fs::File::open(path).map_err(io)?;
    let n = file.read(&mut magic).map_err(io)?;
    let named = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"));
    Ok(&magic[..n] == MCAP_MAGIC || named)
}

impl Recording {
    /// One line for logs: the kind, path, topic and frame count.
    pub fn describe(&self) -> String {
        match self {
            Self::PcdDir(d) => format!(
                "frame directory {} ({} frames{})",
                d.dir().display(),
                d.len(),
                if d.has_truth() { ", truth.csv" } else { "" }
            ),
            Self::Mcap(m) => {
                let (topic, kind) = m.topic();
                let count = m
                    .message_count()
                    .map_or(String::new(), |n| format!(", {n} messages"));
                format!("{} topic {topic} ({kind:?}{count})", m.path().display())
            }
        }
    }

    /// The number of frames, when known before reading.
    pub fn len_hint(&self) -> Option<usize> {
        match self {
            Self::PcdDir(d) => Some(d.len()),
            Self::Mcap(m) => m.message_count().and_then(|n| usize::try_from(n).ok()),
        }
    }

    /// The frames in order. An error concerns one frame (or one broken
    /// file of a bag): it is yielded and the iteration goes on.
    pub fn frames(&mut self) -> Box<dyn Iterator<Item = Result<InputFrame, InputError>> + '_> {
        match self {
            Self::PcdDir(d) => Box::new(d.iter()),
            Self::Mcap(m) => Box::new(m.frames()),
        }
    }

    /// Problems found when opening (a corrupt `truth.csv`), not fatal.
    pub fn warnings(&self) -> &[InputError] {
        match self {
            Self::PcdDir(d) => d.warnings(),
            Self::Mcap(_) => &[],
        }
    }

    /// True when the recording holds truth (`truth.csv` of a frame directory).
    pub fn has_truth(&self) -> bool {
        matches!(self, Self::PcdDir(d) if d.has_truth())
    }
}
