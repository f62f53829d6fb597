//! What a spacepose recording holds for a replay: the descriptor it ran,
//! the sequence of every raw cloud in order, and the poses and acquisitions
//! the suite published.

use anyhow::{Context, Result};
use serde::Deserialize;
use spacepose_foxglove::AcquisitionRecord;
use spacepose_foxglove::topics::{ACQUISITION, POSE_ESTIMATE, RAW_CLOUD_HEADER};
use spacepose_messages::telemetry::TelemetryPose;
use std::path::Path;

/// The attachment holding the descriptor of the recorded run.
pub const DESCRIPTOR_ATTACHMENT: &str = "descriptor.toml";

/// A recorded run, as far as a replay needs it.
#[derive(Debug, Clone, Default)]
pub struct RecordedRun {
    /// The descriptor the run was started with, when recorded.
    pub descriptor: Option<String>,
    /// Sequence of each raw cloud, in recorded order.
    pub raw_sequences: Vec<u64>,
    /// Every pose published, in recorded order.
    pub poses: Vec<TelemetryPose>,
    /// Every acquisition published, in recorded order.
    pub acquisitions: Vec<AcquisitionRecord>,
    /// Messages that could not be parsed (skipped).
    pub unreadable: usize,
}

#[derive(Deserialize)]
struct Sequence {
    sequence: u64,
}

impl RecordedRun {
    /// Reads `path`, an MCAP file written by the spacepose recorder.
    ///
    /// # Errors
    /// The file cannot be read or is corrupt.
    pub fn read(path: &Path) -> Result<Self> {
        let contents =
            spacepose_input::read_messages(path, &[RAW_CLOUD_HEADER, POSE_ESTIMATE, ACQUISITION])
                .with_context(|| format!("reading the recording {}", path.display()))?;
        let mut run = RecordedRun {
            descriptor: contents
                .attachment(DESCRIPTOR_ATTACHMENT)
                .map(|d| String::from_utf8_lossy(d).into_owned()),
            ..RecordedRun::default()
        };
        for m in &contents.messages {
            let parsed = match m.topic.as_str() {
                RAW_CLOUD_HEADER => serde_json::from_slice::<Sequence>(&m.data)
                    .map(|s| run.raw_sequences.push(s.sequence)),
                POSE_ESTIMATE => serde_json::from_slice(&m.data).map(|p| run.poses.push(p)),
                _ => serde_json::from_slice(&m.data).map(|a| run.acquisitions.push(a)),
            };
            if parsed.is_err() {
                run.unreadable += 1;
            }
        }
        Ok(run)
    }

    /// The recorded raw clouds were decimated (`raw_cloud_every` > 1), or
    /// some are missing: the replay cannot give the suite the same frames.
    pub fn raw_gaps(&self) -> usize {
        self.raw_sequences
            .windows(2)
            .filter(|w| w[1] != w[0] + 1)
            .count()
    }
}
