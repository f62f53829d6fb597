//! [`Logger`]: the suite's messages onto the channels of one SDK context,
//! at sensor-clock times. The MCAP [`crate::Recorder`] and the live
//! [`crate::LiveView`] both log through it, so a file and the live link
//! carry the same channels with the same messages.

use crate::channels::Channels;
use crate::cloud::CloudHeaderRecord;
use crate::error::RecordError;
use crate::pose::SensorPose;
use crate::records::AcquisitionRecord;
use crate::scene::{TargetMesh, target_scene};
use crate::stamp::log_time_ns;
use crate::topics::{TARGET_FRAME, TARGET_TRUTH_FRAME};
use foxglove::messages::PointCloud;
use foxglove::{Context, PartialMetadata};
use spacepose_messages::telemetry::{
    TelemetryFilter, TelemetryHealth, TelemetryPose, TelemetryTruth,
};
use spacepose_messages::{Cloud, FilterState, Message, PoseEstimate, Topic, TruthMsg};
use std::sync::Arc;

/// Whether `cloud` is kept when every `raw_every`-th raw cloud and every
/// `cloud_every`-th cropped cloud is (by sequence; 0: none): the one frame
/// decimation of the file and the live view.
pub(crate) fn keeps_cloud(cloud: &Cloud<'_>, raw_every: u64, cloud_every: u64) -> bool {
    let every = if cloud.topic == Topic::RawCloud {
        raw_every
    } else {
        cloud_every
    };
    every != 0 && cloud.header.sequence.is_multiple_of(every)
}

/// The channels of a context and the log-time bookkeeping.
pub(crate) struct Logger {
    channels: Channels,
    /// Newest sensor time logged (ns): the log time of heartbeats.
    newest_ns: u64,
    /// The target model, kept to be sent again on request.
    mesh: Option<TargetMesh>,
    /// The scene is sent at the log time of the next message.
    scene_due: bool,
}

impl Logger {
    /// Declares the channels in `ctx`.
    pub(crate) fn new(ctx: &Arc<Context>) -> Result<Self, RecordError> {
        Ok(Self {
            channels: Channels::new(ctx)?,
            newest_ns: 0,
            mesh: None,
            scene_due: false,
        })
    }

    /// The target model: sent with the next message logged.
    pub(crate) fn set_target(&mut self, mesh: TargetMesh) {
        self.mesh = Some(mesh);
        self.scene_due = true;
    }

    /// Sends the target model again with the next message (a new subscriber).
    pub(crate) fn resend_scene(&mut self) {
        self.scene_due = self.mesh.is_some();
    }

    /// Newest sensor time logged (ns).
    pub(crate) fn newest_ns(&self) -> u64 {
        self.newest_ns
    }

    /// Advances the newest sensor time and sends a due scene.
    fn at(&mut self, log_ns: u64) -> u64 {
        self.newest_ns = self.newest_ns.max(log_ns);
        if self.scene_due
            && let Some(mesh) = &self.mesh
        {
            let scene = target_scene(mesh, log_ns as f64 * 1e-9);
            self.channels
                .scene
                .log_with_meta(&scene, PartialMetadata::with_log_time(log_ns));
            self.scene_due = false;
        }
        log_ns
    }

    /// Logs `message` (the points of `cloud` kept, `points` of them) on the
    /// cloud's channel and its header beside it, at the scan end.
    pub(crate) fn cloud(
        &mut self,
        cloud: &Cloud<'_>,
        message: &PointCloud,
        points: usize,
    ) -> Result<(), RecordError> {
        let t = self.at(log_time_ns(cloud.header.scan_end_s));
        let header = CloudHeaderRecord::new(cloud.header, points);
        let ch = &self.channels;
        let (points_ch, header_ch) = if cloud.topic == Topic::RawCloud {
            (&ch.raw_cloud, &ch.raw_cloud_header)
        } else {
            (&ch.cloud, &ch.cloud_header)
        };
        points_ch.log_with_meta(message, PartialMetadata::with_log_time(t));
        header_ch.log(&header, t)
    }

    /// Logs a fixed-size message on its channels; `Ok(false)` for commands,
    /// which are not logged.
    pub(crate) fn message(&mut self, msg: &Message) -> Result<bool, RecordError> {
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
            Message::Command(_) => return Ok(false),
        }
        Ok(true)
    }

    fn pose(&mut self, m: &PoseEstimate) -> Result<(), RecordError> {
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

    fn filter_state(&mut self, m: &FilterState) -> Result<(), RecordError> {
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

    fn truth(&mut self, m: &TruthMsg) -> Result<(), RecordError> {
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
}
