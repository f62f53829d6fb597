//! `spacepose track --out RUN.mcap`: the run as the suite's recorder writes
//! it (Foxglove schemas, `spacepose-foxglove`): each raw frame, and
//! everything the pipeline published for it, with the target model.

use anyhow::{Context, Result};
use spacepose_foxglove::{RecordOptions, Recorder, TargetMesh};
use spacepose_messages::{Cloud, CloudHeader, Topic};
use spacepose_runtime::Envelope;
use std::path::Path;

/// An MCAP file of the offline run.
pub struct McapOut(Recorder);

impl McapOut {
    /// Creates `path` (an existing file is an error) with the model of
    /// `target`.
    pub fn create(path: &Path, target: &spacepose_model::Target) -> Result<Self> {
        let mut recorder = Recorder::create(path, RecordOptions::default())
            .with_context(|| format!("creating {}", path.display()))?;
        recorder.set_target(TargetMesh::of(target));
        Ok(McapOut(recorder))
    }

    /// One frame: its raw cloud, then what the nodes sent.
    pub fn frame(
        &mut self,
        header: &CloudHeader,
        points: &[spacepose_geometry::Point],
        sent: &[Envelope],
    ) -> Result<()> {
        let raw = Cloud {
            topic: Topic::RawCloud,
            header,
            points,
        };
        self.0.cloud(raw)?;
        for e in sent {
            match e {
                Envelope::Message(m) => self.0.message(m)?,
                Envelope::Cloud {
                    topic,
                    header,
                    points,
                } => {
                    let cloud = Cloud {
                        topic: *topic,
                        header,
                        points,
                    };
                    self.0.cloud(cloud)?;
                }
                Envelope::Json { .. } => {}
            }
        }
        Ok(())
    }

    /// Closes the file; says how many messages it holds.
    pub fn close(self) -> Result<String> {
        let stats = self.0.close()?;
        Ok(format!(
            "{} clouds and {} messages",
            stats.clouds, stats.messages
        ))
    }
}
