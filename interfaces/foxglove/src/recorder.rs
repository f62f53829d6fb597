//! [`Recorder`]: the suite's messages and clouds into one MCAP file.

use crate::channels::Channels;
use crate::cloud::{CloudHeaderRecord, point_cloud};
use crate::error::RecordError;
use crate::pose::SensorPose;
use crate::records::AcquisitionRecord;
use crate::scene::{TargetMesh, target_scene};
use crate::stamp::log_time_ns;
use crate::topics::{TARGET_FRAME, TARGET_TRUTH_FRAME};
use foxglove::{
    Context, McapAttachment, McapCompression, McapWriteOptions, McapWriterHandle, PartialMetadata,
};
use spacepose_messages::telemetry::{
    TelemetryFilter, TelemetryHealth, TelemetryPose, TelemetryTruth,
};
use spacepose_messages::{Cloud, Message, Topic};
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
    channels: Channels,
    /// Keeps the channels' context alive for the writer's lifetime.
    _context: Arc<Context>,
    /// Newest sensor time recorded (ns): the log time of heartbeats.
    newest_ns: u64,
    /// The target mesh, until it is sent with the first message.
    pending_scene: Option<TargetMesh>,
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
        let channels = Channels::new(&context)?;
        Ok(Self {
            path: path_str,
            options,
            writer,
            channels,
            _context: context,
            newest_ns: 0,
            pending_scene: None,
            stats: RecordStats::default(),
        })
    }

    /// The target model, placed at the estimated and true poses: sent once,
    /// at the log time of the next message recorded.
    pub fn set_target(&mut self, mesh: TargetMesh) {
        self.pending_scene = Some(mesh);
    }

    /// What was recorded so far.
    pub fn stats(&self) -> RecordStats {
        self.stats
    }

    /// Advances the newest sensor time and sends the pending scene.
    fn at(&mut self, log_ns: u64) -> u64 {
        self.newest_ns = self.newest_ns.max(log_ns);
        if let Some(mesh) = self.pending_scene.take() {
            let scene = target_scene(&mesh, log_ns as f64 * 1e-9);
            self.channels
                .scene
                .log_with_meta(&scene, PartialMetadata::with_log_time(log_ns));
        }
        log_ns
    }

    /// Records a cloud (raw or cropped) and its header at the scan end,
    /// unless the decimation skips its frame. Returns whether it was recorded.
    ///
    /// # Errors
    /// The header could not be written as JSON.
    pub fn cloud(&mut self, cloud: Cloud<'_>) -> Result<bool, RecordError> {
        let raw = cloud.topic == Topic::RawCloud;
        let every = if raw {
            self.options.raw_cloud_every
        } else {
            self.options.cloud_every
        };
        if every == 0 || !cloud.header.sequence.is_multiple_of(every) {
            self.stats.clouds_skipped += 1;
            return Ok(false);
        }
        let t = self.at(log_time_ns(cloud.header.scan_end_s));
        let message = point_cloud(cloud.points, cloud.header.scan_end_s);
        let header = CloudHeaderRecord::new(cloud.header, cloud.points.len());
        let meta = PartialMetadata::with_log_time(t);
        let ch = &self.channels;
        let (points, header_ch) = if raw {
            (&ch.raw_cloud, &ch.raw_cloud_header)
        } else {
            (&ch.cloud, &ch.cloud_header)
        };
        points.log_with_meta(&message, meta);
        header_ch.log(&header, t)?;
        self.stats.clouds += 1;
        Ok(true)
    }

    /// Records a fixed-size message on its channels (commands are not recorded).
    ///
    /// # Errors
    /// A message with unknown codes or a degenerate rotation.
    pub fn message(&mut self, msg: &Message) -> Result<(), RecordError> {
        match msg {
            Message::Pose(m) => self.pose(m)?,
            Message::FilterState(m) => self.filter_state(m)?,
            Message::Acquisition(m) => {
                let record = AcquisitionRecord::from_wire(m)?;
                let t = self.at(log_time_ns(m.t_s));
                self.channels.acquisition.log(&record, t)?;
            }
            Message::Truth(m) => self.truth(m)?,
            Message::Health(m) => {
                let record = TelemetryHealth::from_wire(m)?;
                let t = self.at(self.newest_ns);
                self.channels.health.log(&record, t)?;
            }
            Message::Command(_) => return Ok(()),
        }
        self.stats.messages += 1;
        Ok(())
    }

    fn pose(&mut self, m: &spacepose_messages::PoseEstimate) -> Result<(), RecordError> {
        let record = TelemetryPose::from_wire(m)?;
        let t = self.at(log_time_ns(m.t_s));
        let pose = SensorPose::from(m);
        let meta = PartialMetadata::with_log_time(t);
        self.channels
            .pose
            .log_with_meta(&pose.pose_in_frame(), meta);
        self.channels
            .pose_tf
            .log_with_meta(&pose.transform_to(TARGET_FRAME), meta);
        self.channels.pose_estimate.log(&record, t)
    }

    fn filter_state(&mut self, m: &spacepose_messages::FilterState) -> Result<(), RecordError> {
        let record = TelemetryFilter::from_wire(m)?;
        let initialized = m.initialized == 1;
        let t = self.at(if initialized {
            log_time_ns(m.t_s)
        } else {
            self.newest_ns
        });
        if initialized {
            let pose = SensorPose::from(m).pose_in_frame();
            self.channels
                .filter_pose
                .log_with_meta(&pose, PartialMetadata::with_log_time(t));
        }
        self.channels.filter_state.log(&record, t)
    }

    fn truth(&mut self, m: &spacepose_messages::TruthMsg) -> Result<(), RecordError> {
        let record = TelemetryTruth::from_wire(m)?;
        let t = self.at(log_time_ns(m.t_s));
        let pose = SensorPose::from(m);
        let meta = PartialMetadata::with_log_time(t);
        self.channels
            .truth
            .log_with_meta(&pose.pose_in_frame(), meta);
        self.channels
            .truth_tf
            .log_with_meta(&pose.transform_to(TARGET_TRUTH_FRAME), meta);
        self.channels.truth_state.log(&record, t)
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
            log_time: self.newest_ns,
            create_time: self.newest_ns,
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
