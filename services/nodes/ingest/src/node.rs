//! The ingest node: the latest prediction in, cropped frames out.

use crate::config::IngestServiceConfig;
use crate::wire::{from_acquisition, from_filter_state};
use spacepose_geometry::Point;
use spacepose_ingest::{FrameReport, IngestError, IngestStage, TargetPrediction};
use spacepose_messages::{Cloud, Message, MessageError, ServiceKind, Topic};
use spacepose_runtime::{Counters, Ctx, Node, NodeInfo};
use tracing::{info, warn};

/// Crops every raw frame around the latest prediction.
pub struct IngestNode {
    stage: IngestStage,
    prediction: Option<TargetPrediction>,
    buffer: Vec<Point>,
    /// Whether the last forwarded frame showed the target (for the log).
    target_seen: bool,
}

impl Node for IngestNode {
    const KIND: ServiceKind = ServiceKind::Ingest;
    type Config = IngestServiceConfig;

    fn new(config: IngestServiceConfig, _: &NodeInfo) -> anyhow::Result<Self> {
        Ok(IngestNode {
            stage: IngestStage::new(config.crop_config()?)?,
            prediction: None,
            buffer: Vec::new(),
            target_seen: true,
        })
    }

    fn on_message(&mut self, msg: &Message, ctx: &mut Ctx<'_>) {
        let candidate = match msg {
            Message::FilterState(s) => from_filter_state(s),
            Message::Acquisition(a) => from_acquisition(a),
            _ => return,
        };
        self.update_prediction(candidate, ctx.counters);
    }

    fn on_cloud(&mut self, cloud: Cloud<'_>, ctx: &mut Ctx<'_>) {
        let header = *cloud.header;
        ctx.counters.frames_in += 1;
        let result = self.stage.process_into(
            cloud.points,
            header.scan_start_s,
            header.scan_end_s,
            self.prediction.as_ref(),
            &mut self.buffer,
        );
        match result {
            Ok(report) => {
                if report.non_finite_points > 0 {
                    ctx.counters.rejected_non_finite += 1;
                    warn!(
                        sequence = header.sequence,
                        "dropped {} non-finite points", report.non_finite_points
                    );
                }
                self.log_target_seen(header.sequence, &report);
                if ctx.send_cloud(Topic::Cloud, header, &self.buffer) {
                    ctx.counters.frames_out += 1;
                    ctx.counters.last_frame = header.sequence;
                }
            }
            Err(e) => {
                warn!(sequence = header.sequence, "frame rejected: {e}");
                count_rejection(&e, ctx.counters);
            }
        }
    }
}

impl IngestNode {
    /// The prediction the next frame is cropped around.
    pub fn prediction(&self) -> Option<&TargetPrediction> {
        self.prediction.as_ref()
    }

    /// Keeps the most recent valid prediction; a bad one is counted.
    fn update_prediction(
        &mut self,
        candidate: Result<Option<TargetPrediction>, MessageError>,
        counters: &mut Counters,
    ) {
        match candidate {
            Ok(Some(p)) if p.is_finite() => {
                if self.prediction.is_none_or(|old| p.t_s >= old.t_s) {
                    self.prediction = Some(p);
                }
            }
            Ok(Some(_)) => {
                warn!("non-finite prediction ignored");
                counters.errors += 1;
            }
            Ok(None) => {}
            Err(e) => {
                warn!("prediction ignored: {e}");
                counters.errors += 1;
            }
        }
    }

    /// Logs when the target disappears from the frames and when it is back.
    fn log_target_seen(&mut self, sequence: u64, report: &FrameReport) {
        if report.target_seen == self.target_seen {
            return;
        }
        self.target_seen = report.target_seen;
        let without = self.stage.stats().frames_without_target;
        if report.target_seen {
            info!(
                sequence,
                points = report.output_points,
                frames_without_target = without,
                "target seen again"
            );
        } else {
            info!(
                sequence,
                input_points = report.input_points,
                points = report.output_points,
                "target not seen: forwarding the frame as an observation"
            );
        }
    }
}

/// A rejected frame in the health counters (as the stage counts it in its
/// statistics). Empty frames are forwarded, not rejected, so
/// `rejected_empty` stays 0; `frames_without_target` is in the stage's
/// statistics and the log.
fn count_rejection(e: &IngestError, c: &mut Counters) {
    match e {
        IngestError::Oversized { .. } => c.rejected_oversized += 1,
        IngestError::AllNonFinite { .. } => c.rejected_non_finite += 1,
        _ => c.errors += 1,
    }
}
