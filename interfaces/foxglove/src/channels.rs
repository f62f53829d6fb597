//! The channels of a recording, declared once in the recorder's context.

use crate::cloud::CloudHeaderRecord;
use crate::error::RecordError;
use crate::json::schema_of;
use crate::records::AcquisitionRecord;
use crate::topics;
use foxglove::messages::{FrameTransform, PointCloud, PoseInFrame, SceneUpdate};
use foxglove::{Channel, Context, PartialMetadata, RawChannel, Schema};
use serde::Serialize;
use spacepose_messages::telemetry::{
    TelemetryFilter, TelemetryHealth, TelemetryPose, TelemetryTruth,
};
use spacepose_messages::{
    AcquisitionResult, CloudHeader, FilterState, Health, Name, PoseEstimate, TruthMsg,
};
use std::sync::Arc;

/// A JSON channel (`json` encoding, `jsonschema` schema).
pub(crate) struct JsonChannel(Arc<RawChannel>);

impl JsonChannel {
    fn new(
        ctx: &Arc<Context>,
        topic: &str,
        title: &str,
        sample: &impl Serialize,
    ) -> Result<Self, RecordError> {
        let schema = schema_of(title, &serde_json::to_value(sample)?);
        let channel = ctx
            .channel_builder(topic)
            .message_encoding("json")
            .schema(Schema::new(
                title,
                "jsonschema",
                serde_json::to_vec(&schema)?,
            ))
            .build_raw()
            .map_err(|source| RecordError::Channel {
                topic: topic.to_string(),
                source,
            })?;
        Ok(Self(channel))
    }

    /// Logs `record` as JSON at `log_time_ns`.
    pub(crate) fn log(&self, record: &impl Serialize, log_time_ns: u64) -> Result<(), RecordError> {
        let json = serde_json::to_vec(record)?;
        self.0
            .log_with_meta(&json, PartialMetadata::with_log_time(log_time_ns));
        Ok(())
    }
}

/// Every channel of a recording.
pub(crate) struct Channels {
    pub(crate) raw_cloud: Channel<PointCloud>,
    pub(crate) raw_cloud_header: JsonChannel,
    pub(crate) cloud: Channel<PointCloud>,
    pub(crate) cloud_header: JsonChannel,
    pub(crate) pose: Channel<PoseInFrame>,
    pub(crate) pose_estimate: JsonChannel,
    pub(crate) pose_tf: Channel<FrameTransform>,
    pub(crate) filter_state: JsonChannel,
    pub(crate) filter_pose: Channel<PoseInFrame>,
    pub(crate) acquisition: JsonChannel,
    pub(crate) health: JsonChannel,
    pub(crate) truth: Channel<PoseInFrame>,
    pub(crate) truth_tf: Channel<FrameTransform>,
    pub(crate) truth_state: JsonChannel,
    pub(crate) scene: Channel<SceneUpdate>,
}

impl Channels {
    /// Declares every channel in `ctx`; JSON schemas come from sample records.
    pub(crate) fn new(ctx: &Arc<Context>) -> Result<Self, RecordError> {
        let header = CloudHeaderRecord::new(&CloudHeader::new(0, 0.0, 0.0), 0);
        let name = Name::new("sample")?;
        let health = TelemetryHealth::from_wire(&Health::new(name, name, 0))?;
        Ok(Self {
            raw_cloud: ctx.channel_builder(topics::RAW_CLOUD).build(),
            raw_cloud_header: JsonChannel::new(
                ctx,
                topics::RAW_CLOUD_HEADER,
                "spacepose.CloudHeader",
                &header,
            )?,
            cloud: ctx.channel_builder(topics::CLOUD).build(),
            cloud_header: JsonChannel::new(
                ctx,
                topics::CLOUD_HEADER,
                "spacepose.CloudHeader",
                &header,
            )?,
            pose: ctx.channel_builder(topics::POSE).build(),
            pose_estimate: JsonChannel::new(
                ctx,
                topics::POSE_ESTIMATE,
                "spacepose.PoseEstimate",
                &TelemetryPose::from_wire(&PoseEstimate::new())?,
            )?,
            pose_tf: ctx.channel_builder(topics::POSE_TF).build(),
            filter_state: JsonChannel::new(
                ctx,
                topics::FILTER_STATE,
                "spacepose.FilterState",
                &TelemetryFilter::from_wire(&FilterState::new())?,
            )?,
            filter_pose: ctx.channel_builder(topics::FILTER_POSE).build(),
            acquisition: JsonChannel::new(
                ctx,
                topics::ACQUISITION,
                "spacepose.Acquisition",
                &AcquisitionRecord::from_wire(&AcquisitionResult::new())?,
            )?,
            health: JsonChannel::new(ctx, topics::HEALTH, "spacepose.Health", &health)?,
            truth: ctx.channel_builder(topics::TRUTH).build(),
            truth_tf: ctx.channel_builder(topics::TRUTH_TF).build(),
            truth_state: JsonChannel::new(
                ctx,
                topics::TRUTH_STATE,
                "spacepose.Truth",
                &TelemetryTruth::from_wire(&TruthMsg::new())?,
            )?,
            scene: ctx.channel_builder(topics::SCENE).build(),
        })
    }
}
