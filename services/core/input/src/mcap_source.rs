//! Point clouds from MCAP files and ROS 2 bags (a directory with
//! `metadata.yaml` and `*.mcap`), in file order.
//!
//! Files are read whole into memory. Messages of the chosen topic are
//! decoded one by one; for spacepose's own Foxglove clouds the JSON header
//! on `<topic>/header` with the same log time is paired with its cloud.

use crate::bounded::BoundedMessages;
use crate::channels::{ChannelInfo, CloudKind, channels_of, choose};
use crate::chunks::check_chunk_sizes;
use crate::error::{CloudError, InputError};
use crate::foxglove_cloud::{HEADER_TOPIC_SUFFIX, SpaceposeHeader, parse_header};
use crate::frame::InputFrame;
use crate::options::InputOptions;
use crate::pointcloud2::DecodedCloud;
use crate::{foxglove_cloud, pointcloud2};
use mcap::Message;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// An opened MCAP file or ROS 2 bag, with its point-cloud channel chosen.
#[derive(Debug)]
pub struct McapSource {
    path: PathBuf,
    files: Vec<(PathBuf, Vec<u8>)>,
    channels: Vec<ChannelInfo>,
    topic: String,
    kind: CloudKind,
    header_topic: Option<String>,
    options: InputOptions,
}

impl McapSource {
    /// Reads `files` (one MCAP file, or the `.mcap` files of a bag in
    /// order) and chooses the point-cloud channel. `path` names the recording.
    ///
    /// # Errors
    /// [`InputError::Io`], [`InputError::Mcap`] for an unreadable file,
    /// [`InputError::Topic`] when no channel can be chosen.
    pub fn open(
        path: &Path,
        files: &[PathBuf],
        options: &InputOptions,
    ) -> Result<Self, InputError> {
        let mut loaded = Vec::new();
        let mut channels = Vec::new();
        for file in files {
            let buf = std::fs::read(file).map_err(|source| InputError::Io {
                path: file.clone(),
                source,
            })?;
            check_chunk_sizes(file, &buf)?;
            channels.extend(channels_of(file, &buf)?);
            loaded.push((file.clone(), buf));
        }
        let (topic, kind) = choose(path, &channels, options.topic.as_deref())?;
        let wanted = format!("{topic}{HEADER_TOPIC_SUFFIX}");
        let header_topic = (kind == CloudKind::FoxglovePointCloud
            && channels.iter().any(|c| c.topic == wanted))
        .then_some(wanted);
        Ok(McapSource {
            path: path.to_owned(),
            files: loaded,
            channels,
            topic,
            kind,
            header_topic,
            options: options.clone(),
        })
    }

    /// The recording's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The chosen topic and how it is decoded.
    pub fn topic(&self) -> (&str, CloudKind) {
        (&self.topic, self.kind)
    }

    /// Every channel of every file.
    pub fn channels(&self) -> &[ChannelInfo] {
        &self.channels
    }

    /// True when spacepose headers (`<topic>/header`) give the scan times.
    pub fn has_spacepose_headers(&self) -> bool {
        self.header_topic.is_some()
    }

    /// Messages on the chosen topic, when every file's statistics say.
    pub fn message_count(&self) -> Option<u64> {
        self.channels
            .iter()
            .filter(|c| c.topic == self.topic)
            .map(|c| c.messages)
            .sum()
    }

    /// The frames in file order; errors are yielded in place.
    pub fn frames(&self) -> McapFrames<'_> {
        McapFrames {
            source: self,
            cursor: McapCursor::default(),
        }
    }

    /// The next frame after `cursor` (which then moves past it): the owned
    /// form of [`McapSource::frames`], for a reader that keeps its place
    /// between calls.
    pub fn next_frame(&self, cursor: &mut McapCursor) -> Option<Result<InputFrame, InputError>> {
        cursor.next(self)
    }
}

/// A cloud message waiting for its header.
#[derive(Debug)]
struct Pending {
    log_time_ns: u64,
    data: Vec<u8>,
    rank: u64,
}

/// A place in a [`McapSource`]'s frames: the file, the reader's position in
/// it, and a cloud waiting for its header. Holds no borrow of the source.
#[derive(Default)]
pub struct McapCursor {
    file: usize,
    stream: Option<BoundedMessages>,
    pending: Option<Pending>,
    headers: BTreeMap<u64, Result<SpaceposeHeader, CloudError>>,
    rank: u64,
}

impl std::fmt::Debug for McapCursor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("McapCursor")
            .field("file", &self.file)
            .field("rank", &self.rank)
            .finish_non_exhaustive()
    }
}

/// Iterator over the frames of a [`McapSource`].
pub struct McapFrames<'a> {
    source: &'a McapSource,
    cursor: McapCursor,
}

impl Iterator for McapFrames<'_> {
    type Item = Result<InputFrame, InputError>;

    fn next(&mut self) -> Option<Self::Item> {
        self.cursor.next(self.source)
    }
}

impl McapCursor {
    /// The next frame of `source`.
    fn next(&mut self, source: &McapSource) -> Option<Result<InputFrame, InputError>> {
        loop {
            let Some(message) = self.next_message(source) else {
                return self.pending.take().map(|p| self.emit(source, p));
            };
            let message = match message {
                Ok(m) => m,
                Err(e) => return Some(Err(e)),
            };
            let topic = message.channel.topic.as_str();
            if topic == source.topic {
                let cloud = Pending {
                    log_time_ns: message.log_time,
                    data: message.data.into_owned(),
                    rank: self.rank,
                };
                self.rank += 1;
                if source.header_topic.is_none() {
                    return Some(self.emit(source, cloud));
                }
                if let Some(previous) = self.pending.replace(cloud) {
                    return Some(self.emit(source, previous));
                }
            } else if Some(topic) == source.header_topic.as_deref() {
                self.headers
                    .insert(message.log_time, parse_header(&message.data));
                if self
                    .pending
                    .as_ref()
                    .is_some_and(|p| p.log_time_ns == message.log_time)
                {
                    return self.pending.take().map(|p| self.emit(source, p));
                }
            }
        }
    }

    /// The next message of any channel, across files; a broken file yields
    /// its error once and the reading goes on with the next file.
    fn next_message(
        &mut self,
        source: &McapSource,
    ) -> Option<Result<Message<'static>, InputError>> {
        loop {
            let (path, buf) = source.files.get(self.file)?;
            let stream = self
                .stream
                .get_or_insert_with(|| BoundedMessages::new(buf.len()));
            match stream.next_in(buf) {
                Some(Ok(m)) => return Some(Ok(m)),
                Some(Err(e)) => {
                    self.stream = None;
                    self.file += 1;
                    return Some(Err(mcap_error(path, e)));
                }
                None => {
                    self.stream = None;
                    self.file += 1;
                }
            }
        }
    }

    /// Decodes a cloud (with its header, if one came) into a frame.
    fn emit(&mut self, source: &McapSource, cloud: Pending) -> Result<InputFrame, InputError> {
        let header = self.headers.remove(&cloud.log_time_ns);
        self.headers = self.headers.split_off(&cloud.log_time_ns);
        let fail = |source_error| InputError::Message {
            topic: source.topic.clone(),
            log_time_ns: cloud.log_time_ns,
            source: source_error,
        };
        let header = header.transpose().map_err(fail)?;
        let decoded: DecodedCloud = match source.kind {
            CloudKind::Ros2PointCloud2 => pointcloud2::decode(&cloud.data, &source.options),
            CloudKind::FoxglovePointCloud => {
                foxglove_cloud::decode(&cloud.data, header.as_ref(), &source.options)
            }
        }
        .map_err(fail)?;
        Ok(InputFrame {
            index: header.map_or(cloud.rank, |h| h.sequence),
            origin: format!("{} @ {} ns", source.topic, cloud.log_time_ns),
            frame_id: decoded.frame_id,
            points: decoded.points,
            scan_start_s: decoded.scan_s.0,
            scan_end_s: decoded.scan_s.1,
            scan_time_source: decoded.scan_time_source,
            point_times: decoded.point_times,
            dropped_non_finite: decoded.dropped_non_finite,
        })
    }
}

fn mcap_error(path: &Path, e: mcap::McapError) -> InputError {
    InputError::Mcap {
        path: path.to_owned(),
        message: e.to_string(),
    }
}

/// The `.mcap` files of a ROS 2 bag directory, in split order
/// (`name_0.mcap`, `name_1.mcap`, … `name_10.mcap`).
///
/// # Errors
/// [`InputError::Io`], or [`InputError::Mcap`] when there is none (a
/// sqlite3 bag: only MCAP storage is read).
pub(crate) fn bag_files(dir: &Path) -> Result<Vec<PathBuf>, InputError> {
    let io = |source| InputError::Io {
        path: dir.to_owned(),
        source,
    };
    let mut files: Vec<(u64, PathBuf)> = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let path = entry.map_err(io)?.path();
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
        {
            files.push((split_number(&path), path));
        }
    }
    if files.is_empty() {
        return Err(InputError::Mcap {
            path: dir.to_owned(),
            message: "no .mcap file in this ROS 2 bag (only MCAP storage is read, not sqlite3)"
                .into(),
        });
    }
    files.sort();
    Ok(files.into_iter().map(|(_, p)| p).collect())
}

/// The trailing number of a file stem (`bag_12` → 12), 0 without one.
fn split_number(path: &Path) -> u64 {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let digits: String = stem
        .chars()
        .rev()
        .take_while(char::is_ascii_digit)
        .collect();
    digits
        .chars()
        .rev()
        .collect::<String>()
        .parse()
        .unwrap_or(0)
}

#[cfg(test)]
#[path = "mcap_source_tests.rs"]
mod tests;
