//! Undecoded messages of chosen topics and the attachments of one MCAP
//! file, read with the same bounded reader as the clouds: what a tool needs
//! to compare a run with its recording (`spacepose replay`).

use crate::bounded::BoundedMessages;
use crate::chunks::check_chunk_sizes;
use crate::error::InputError;
use std::path::Path;

/// A message of one of the chosen topics, as recorded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TopicMessage {
    /// Its channel's topic.
    pub topic: String,
    /// Its log time (ns).
    pub log_time_ns: u64,
    /// Its payload, undecoded.
    pub data: Vec<u8>,
}

/// The messages of the chosen topics in file order, and every attachment.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct McapContents {
    /// Messages of the chosen topics.
    pub messages: Vec<TopicMessage>,
    /// Attachments: name and data.
    pub attachments: Vec<(String, Vec<u8>)>,
}

impl McapContents {
    /// The data of the first attachment named `name`.
    pub fn attachment(&self, name: &str) -> Option<&[u8]> {
        self.attachments
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, d)| d.as_slice())
    }

    /// The messages on `topic`, in file order.
    pub fn on<'a>(&'a self, topic: &'a str) -> impl Iterator<Item = &'a TopicMessage> + 'a {
        self.messages.iter().filter(move |m| m.topic == topic)
    }
}

/// Reads the messages on `topics` and the attachments of the MCAP file
/// `path`.
///
/// # Errors
/// [`InputError::Io`] for an unreadable file, [`InputError::Mcap`] for a
/// corrupt one (anywhere in it: the contents are wanted whole).
pub fn read_messages(path: &Path, topics: &[&str]) -> Result<McapContents, InputError> {
    let buf = std::fs::read(path).map_err(|source| InputError::Io {
        path: path.to_owned(),
        source,
    })?;
    check_chunk_sizes(path, &buf)?;
    let mut stream = BoundedMessages::new(buf.len());
    let mut messages = Vec::new();
    while let Some(message) = stream.next_in(&buf) {
        let message = message.map_err(|e| InputError::Mcap {
            path: path.to_owned(),
            message: e.to_string(),
        })?;
        if topics.contains(&message.channel.topic.as_str()) {
            messages.push(TopicMessage {
                topic: message.channel.topic.clone(),
                log_time_ns: message.log_time,
                data: message.data.into_owned(),
            });
        }
    }
    Ok(McapContents {
        messages,
        attachments: stream.attachments,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chosen_topics_and_attachments_are_read_and_garbage_is_an_error() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("run.mcap");
        let mut w = mcap::Writer::new(std::io::BufWriter::new(
            std::fs::File::create(&path).unwrap(),
        ))
        .unwrap();
        let json = |topic: &str, w: &mut mcap::Writer<_>| {
            w.add_channel(0, topic, "json", &std::collections::BTreeMap::new())
                .unwrap()
        };
        let a = json("/a", &mut w);
        let b = json("/b", &mut w);
        for (channel, t, data) in [(a, 1, b"1"), (b, 2, b"2"), (a, 3, b"3")] {
            let header = mcap::records::MessageHeader {
                channel_id: channel,
                sequence: 0,
                log_time: t,
                publish_time: t,
            };
            w.write_to_known_channel(&header, data).unwrap();
        }
        let attachment = mcap::Attachment {
            log_time: 0,
            create_time: 0,
            name: "descriptor.toml".into(),
            media_type: "application/toml".into(),
            data: std::borrow::Cow::Borrowed(b"prefix = \"x\""),
        };
        w.attach(&attachment).unwrap();
        w.finish().unwrap();
        drop(w);
        let got = read_messages(&path, &["/a"]).unwrap();
        let times: Vec<u64> = got.on("/a").map(|m| m.log_time_ns).collect();
        assert_eq!(times, [1, 3]);
        assert_eq!(got.messages.len(), 2);
        assert_eq!(
            got.attachment("descriptor.toml"),
            Some(&b"prefix = \"x\""[..])
        );
        assert!(got.attachment("other").is_none());
        std::fs::write(&path, b"\x89MCAP0\r\ngarbage").unwrap();
        assert!(read_messages(&path, &["/a"]).is_err());
    }
}
