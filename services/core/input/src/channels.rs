//! The channels of MCAP files, and the choice of the point-cloud channel.

use crate::bounded::BoundedMessages;
use crate::error::InputError;
use crate::{foxglove_cloud, pointcloud2};
use mcap::read::Summary;
use std::collections::BTreeMap;
use std::path::Path;

/// How a channel's messages are decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum CloudKind {
    /// `sensor_msgs/msg/PointCloud2`, CDR.
    Ros2PointCloud2,
    /// `foxglove.PointCloud`, protobuf.
    FoxglovePointCloud,
}

/// A channel of a recording.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChannelInfo {
    /// Topic.
    pub topic: String,
    /// Schema name (empty without a schema).
    pub schema: String,
    /// Message encoding.
    pub message_encoding: String,
    /// Messages on it, when the file's statistics say.
    pub messages: Option<u64>,
}

impl ChannelInfo {
    /// The point-cloud kind of this channel, if it is one.
    pub fn cloud_kind(&self) -> Option<CloudKind> {
        match (self.schema.as_str(), self.message_encoding.as_str()) {
            (pointcloud2::SCHEMA_NAME, "cdr") => Some(CloudKind::Ros2PointCloud2),
            (foxglove_cloud::SCHEMA_NAME, "protobuf") => Some(CloudKind::FoxglovePointCloud),
            _ => None,
        }
    }
}

/// The channels of one file: from its summary, else by reading every
/// message (a file without summary, or truncated).
///
/// # Errors
/// [`InputError::Mcap`] when the file yields no channel and an error.
pub(crate) fn channels_of(path: &Path, buf: &[u8]) -> Result<Vec<ChannelInfo>, InputError> {
    if let Ok(Some(summary)) = Summary::read(buf)
        && !summary.channels.is_empty()
    {
        let counts = summary.stats.map(|s| s.channel_message_counts);
        let mut out: Vec<ChannelInfo> = summary
            .channels
            .values()
            .map(|c| ChannelInfo {
                topic: c.topic.clone(),
                schema: c.schema.as_ref().map_or(String::new(), |s| s.name.clone()),
                message_encoding: c.message_encoding.clone(),
                messages: counts.as_ref().map(|m| m.get(&c.id).copied().unwrap_or(0)),
            })
            .collect();
        out.sort_by(|a, b| a.topic.cmp(&b.topic));
        return Ok(out);
    }
    scan_channels(path, buf)
}

fn scan_channels(path: &Path, buf: &[u8]) -> Result<Vec<ChannelInfo>, InputError> {
    let error = |e: mcap::McapError| InputError::Mcap {
        path: path.to_owned(),
        message: e.to_string(),
    };
    let mut stream = BoundedMessages::new(buf.len());
    let mut seen: BTreeMap<u16, ChannelInfo> = BTreeMap::new();
    while let Some(message) = stream.next_in(buf) {
        let message = match message {
            Ok(m) => m,
            Err(e) if seen.is_empty() => return Err(error(e)),
            Err(_) => break, // reported again, in place, while reading frames
        };
        let c = &message.channel;
        let info = seen.entry(c.id).or_insert_with(|| ChannelInfo {
            topic: c.topic.clone(),
            schema: c.schema.as_ref().map_or(String::new(), |s| s.name.clone()),
            message_encoding: c.message_encoding.clone(),
            messages: Some(0),
        });
        info.messages = info.messages.map(|n| n + 1);
    }
    Ok(seen.into_values().collect())
}

/// The raw clouds of a spacepose recording (`spacepose-foxglove` writes the
/// cropped ones beside them on `/spacepose/cloud`).
pub const SPACEPOSE_RAW_CLOUD: &str = "/spacepose/raw_cloud";

/// Chooses the point-cloud channel: `topic` if given, else the only one,
/// else, in a spacepose recording, its raw clouds ([`SPACEPOSE_RAW_CLOUD`]:
/// what the sensor gave, the input of the pipeline).
///
/// # Errors
/// [`InputError::Topic`] listing the point-cloud topics.
pub(crate) fn choose(
    path: &Path,
    channels: &[ChannelInfo],
    topic: Option<&str>,
) -> Result<(String, CloudKind), InputError> {
    let mut clouds: Vec<(&str, CloudKind, &str)> = channels
        .iter()
        .filter_map(|c| Some((c.topic.as_str(), c.cloud_kind()?, c.schema.as_str())))
        .collect();
    clouds.sort();
    clouds.dedup();
    let topics = clouds
        .iter()
        .map(|(t, _, s)| format!("{t} ({s})"))
        .collect::<Vec<_>>()
        .join(", ");
    let fail = |message: String| InputError::Topic {
        path: path.to_owned(),
        message,
        topics: topics.clone(),
    };
    match topic {
        Some(wanted) => match clouds.iter().find(|(t, _, _)| *t == wanted) {
            Some(&(t, kind, _)) => Ok((t.to_owned(), kind)),
            None => match channels.iter().find(|c| c.topic == wanted) {
                Some(c) => Err(fail(format!(
                    "topic {wanted} holds {:?} ({}), not point clouds",
                    c.schema, c.message_encoding
                ))),
                None => Err(fail(format!("no topic {wanted}"))),
            },
        },
        None => match clouds.as_slice() {
            [(t, kind, _)] => Ok(((*t).to_owned(), *kind)),
            several if several.iter().any(|(t, _, _)| *t == SPACEPOSE_RAW_CLOUD) => several
                .iter()
                .find(|(t, _, _)| *t == SPACEPOSE_RAW_CLOUD)
                .map(|&(t, kind, _)| (t.to_owned(), kind))
                .ok_or_else(|| fail("no raw clouds".into())),
            [] => Err(fail("no point-cloud channel (sensor_msgs/msg/PointCloud2 in CDR, or foxglove.PointCloud)".into())),
            _ => Err(fail("several point-cloud channels: choose one with the topic option".into())),
        },
    }
}
