//! MCAP messages read with a bound on every record length.
//!
//! `mcap::MessageStream` reads records inside chunks without a length
//! limit and allocates what a record header claims, so one corrupt length
//! aborts the process. This reader drives the crate's sans-I/O
//! [`LinearReader`] with a record length limit of the file size, keeps the
//! schemas and channels itself, and yields messages with owned data.

use mcap::read::ChannelAccumulator;
use mcap::records::Record;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::{McapError, McapResult, Message, parse_record};
use std::borrow::Cow;

/// The messages of one in-memory MCAP file, in file order. The reader
/// keeps its position, not the buffer: [`BoundedMessages::next_in`] is
/// given the same file each time, so a cursor can outlive a borrow.
pub(crate) struct BoundedMessages {
    /// Bytes of the file handed to the reader so far.
    pos: usize,
    reader: LinearReader,
    channels: ChannelAccumulator<'static>,
    /// Attachments met so far (name, data), for [`crate::read_messages`].
    pub attachments: Vec<(String, Vec<u8>)>,
    done: bool,
}

impl BoundedMessages {
    /// A reader of a file of `len` bytes, which need not end with the MCAP
    /// magic.
    pub fn new(len: usize) -> Self {
        let options = LinearReaderOptions::default()
            .with_skip_end_magic(true)
            .with_record_length_limit(len);
        BoundedMessages {
            pos: 0,
            reader: LinearReader::new_with_options(options),
            channels: ChannelAccumulator::default(),
            attachments: Vec::new(),
            done: false,
        }
    }

    /// Keeps a schema or channel; returns a message.
    fn record(&mut self, record: Record<'_>) -> McapResult<Option<Message<'static>>> {
        match record {
            Record::Schema { header, data } => {
                self.channels
                    .add_schema(header, Cow::Owned(data.into_owned()))?;
            }
            Record::Channel(c) => self.channels.add_channel(c)?,
            Record::Attachment { header, data, .. } => {
                self.attachments.push((header.name, data.into_owned()));
            }
            Record::Message { header, data } => {
                let channel =
                    self.channels
                        .get(header.channel_id)
                        .ok_or(McapError::UnknownChannel(
                            header.sequence,
                            header.channel_id,
                        ))?;
                return Ok(Some(Message {
                    channel,
                    sequence: header.sequence,
                    log_time: header.log_time,
                    publish_time: header.publish_time,
                    data: Cow::Owned(data.into_owned()),
                }));
            }
            _ => {}
        }
        Ok(None)
    }

    /// The next message of `buf` (the file given to every call), `None` at
    /// its end or after an error.
    pub fn next_in(&mut self, buf: &[u8]) -> Option<McapResult<Message<'static>>> {
        while !self.done {
            let owned = match self.reader.next_event()? {
                Ok(LinearReadEvent::ReadRequest(need)) => {
                    let rest = buf.get(self.pos..).unwrap_or_default();
                    let n = need.min(rest.len());
                    self.reader.insert(n).copy_from_slice(&rest[..n]);
                    self.reader.notify_read(n);
                    self.pos += n;
                    continue;
                }
                Ok(LinearReadEvent::Record { data, opcode }) => {
                    parse_record(opcode, data).map(Record::into_owned)
                }
                Err(e) => Err(e),
            };
            match owned.and_then(|r| self.record(r)) {
                Ok(Some(message)) => return Some(Ok(message)),
                Ok(None) => {}
                Err(e) => {
                    self.done = true;
                    return Some(Err(e));
                }
            }
        }
        None
    }
}
