//! [`Recorder`]: the suite's messages and clouds into one MCAP file.

use crate::cloud::point_cloud;
use crate::error::RecordError;
use crate::log::{Logger, keeps_cloud};
use crate::scene::TargetMesh;
use foxglove::{Context, McapAttachment, McapCompression, McapWriteOptions, McapWriterHandle};
use spacepose_messages::{Cloud, Message};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;
use std::sync::Arc;

/// Chunk compression of the MCAP file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Compression {
    /// LZ4: cheapest on the CPU.
    #[default]
    Lz4,
    /// Zstandard: smaller files.
    Zstd,
    /// None.
    None,
}

/// What to record, and how.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RecordOptions {
    /// Chunk compression.
    pub compression: Compression,
    /// Record the raw cloud of every n-th frame (by sequence); 0: none.
    pub raw_cloud_every: u64,
    /// Record the cropped cloud of every n-th frame (by sequence); 0: none.
    pub cloud_every: u64,
}

impl Default for RecordOptions {
    fn default() -> Self {
        Self {
            compression: Compression::Lz4,
            raw_cloud_every: 1,
            cloud_every: 1,
        }
    }
}

/// Messages written so far, by kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RecordStats {
    /// Clouds recorded.
    pub clouds: u64,
    /// Clouds skipped by the decimation.
    pub clouds_skipped: u64,
    /// Fixed-size messages recorded.
    pub messages: u64,
}

/// An MCAP recording of a run, in its own SDK context (two recorders in
/// one process do not share channels). Closed by [`Recorder::close`], or
/// when dropped (errors then only logged).
pub struct Recorder {
    path: String,
    options: RecordOptions,
    writer: McapWriterHandle<BufWriter<File>>,
    log: Logger,
    /// Keeps the channels' context alive for the writer's lifetime.
    _context: Arc<Context>,
    stats: RecordStats,
}

impl Recorder {
    /// Creates the MCAP file at `path` (an existing file is an error).
    ///
    /// # Errors
    /// The file exists or cannot be created; a channel cannot be declared.
    pub fn create(path: &Path, options: RecordOptions) -> Result<Self, RecordError> {
        let path_str = path.display().to_string();
        let file_err = |source| RecordError::File {
            path: path_str.clone(),
            source,
        };
        let compression = match options.compression {
            Compression::Lz4 => Some(McapCompression::Lz4),
            Compression::Zstd => Some(McapCompression::Zstd),
            Compression::None => None,
        };
        let context = Context::new();
        let writer = context
            .mcap_writer_with_options(McapWriteOptions::new().compression(compression))
            .create_new_buffered_file(path)
            .map_err(file_err)?;
        let log = Logger::new(&context)?;
        Ok(Self {
            path: path_str,
            options,
            writer,
            log,
            _context: context,
            stats: RecordStats::default(),
        })
    }

    /// The target model, placed at the estimated and true poses: sent once,
    /// at the log time of the next message recorded.
    pub fn set_target(&mut self, mesh: TargetMesh) {
        self.log.set_target(mesh);
    }

    /// What was recorded so far.
    pub fn stats(&self) -> RecordStats {
        self.stats
    }

    /// Records a cloud (raw or cropped) and its header at the scan end,
    /// unless the decimation skips its frame. Returns whether it was recorded.
    ///
    /// # Errors
    /// The header could not be written as JSON.
    pub fn cloud(&mut self, cloud: Cloud<'_>) -> Result<bool, RecordError> {
        if !keeps_cloud(
            &cloud,
            self.options.raw_cloud_every,
            self.options.cloud_every,
        ) {
            self.stats.clouds_skipped += 1;
            return Ok(false);
        }
        let message = point_cloud(cloud.points, cloud.header.scan_end_s);
        self.log.cloud(&cloud, &message, cloud.points.len())?;
        self.stats.clouds += 1;
        Ok(true)
    }

    /// Records a fixed-size message on its channels (commands are not recorded).
    ///
    /// # Errors
    /// A message with unknown codes or a degenerate rotation.
    pub fn message(&mut self, msg: &Message) -> Result<(), RecordError> {
        if self.log.message(msg)? {
            self.stats.messages += 1;
        }
        Ok(())
    }

    /// Writes an MCAP metadata record `name` (skipped when `entries` is empty).
    ///
    /// # Errors
    /// The file could not be written.
    pub fn metadata(
        &self,
        name: &str,
        entries: BTreeMap<String, String>,
    ) -> Result<(), RecordError> {
        self.writer
            .write_metadata(name, entries)
            .map_err(|source| self.file_error(source))
    }

    /// Attaches a file (a configuration, the descriptor) to the recording.
    ///
    /// # Errors
    /// The file could not be written.
    pub fn attach(&self, name: &str, media_type: &str, data: &[u8]) -> Result<(), RecordError> {
        let attachment = McapAttachment {
            log_time: self.log.newest_ns(),
            create_time: self.log.newest_ns(),
            name: name.to_string(),
            media_type: media_type.to_string(),
            data: std::borrow::Cow::Borrowed(data),
        };
        self.writer
            .attach(&attachment)
            .map_err(|source| self.file_error(source))
    }

    /// Flushes the current chunk to the file.
    ///
    /// # Errors
    /// The file could not be written.
    pub fn flush(&self) -> Result<(), RecordError> {
        self.writer
            .flush()
            .map_err(|source| self.file_error(source))
    }

    /// Writes the summary and closes the file.
    ///
    /// # Errors
    /// The file could not be written.
    pub fn close(self) -> Result<RecordStats, RecordError> {
        let stats = self.stats;
        let path = self.path;
        self.writer
            .close()
            .map_err(|source| RecordError::File { path, source })?;
        Ok(stats)
    }

    fn file_error(&self, source: foxglove::FoxgloveError) -> RecordError {
        RecordError::File {
            path: self.path.clone(),
            source,
        }
    }
}

#[cfg(test)]
#[path = "recorder_tests.rs"]
mod tests;
