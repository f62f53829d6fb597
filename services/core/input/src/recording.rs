//! [`open`]: any supported recording behind one type.

use crate::error::InputError;
use crate::frame::InputFrame;
use crate::mcap_source::{McapCursor, McapSource, bag_files};
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

/// A place in a [`Recording`]'s frames, kept by a reader between calls of
/// [`Recording::next_frame`] (a replay that publishes one frame per slot).
/// It holds no borrow: a new cursor starts the recording again.
#[derive(Debug)]
pub enum FrameCursor {
    /// The next file of a frame directory.
    PcdDir {
        /// Its index in the directory's frame order.
        next: usize,
    },
    /// A place in an MCAP file or bag.
    Mcap(Box<McapCursor>),
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

    /// A cursor at the first frame.
    pub fn cursor(&self) -> FrameCursor {
        match self {
            Self::PcdDir(_) => FrameCursor::PcdDir { next: 0 },
            Self::Mcap(_) => FrameCursor::Mcap(Box::default()),
        }
    }

    /// The frame at `cursor`, which then moves past it; `None` at the end.
    /// As with [`Recording::frames`], an error concerns one frame and the
    /// next call goes on. A cursor of another kind of recording reads as
    /// the end.
    pub fn next_frame(&self, cursor: &mut FrameCursor) -> Option<Result<InputFrame, InputError>> {
        match (self, cursor) {
            (Self::PcdDir(d), FrameCursor::PcdDir { next }) => {
                let frame = d.read(*next)?;
                *next += 1;
                Some(frame)
            }
            (Self::Mcap(m), FrameCursor::Mcap(c)) => m.next_frame(c),
            _ => None,
        }
    }

    /// The recorded frame period (s) when the recording states one (the
    /// median of a frame directory's `truth.csv`); otherwise a replay paces
    /// frames by their scan start times.
    pub fn recorded_period_s(&self) -> Option<f64> {
        match self {
            Self::PcdDir(d) => d.recorded_period_s(),
            Self::Mcap(_) => None,
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
