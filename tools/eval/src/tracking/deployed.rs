//! The suite in one process: the deployed ingest, tracker and filter nodes
//! wired by the topic graph on a [`LocalBus`], fed the raw frames and the
//! truth acquisition the simulated sensor publishes. Every message crosses
//! the same conversions as between the processes, so a frame is cropped,
//! motion-compensated, voxel-filtered, registered and fused exactly as in
//! the suite (the end-to-end test `frame_path` checks it against the real
//! processes).

use anyhow::{Context, Result};
use spacepose_filter_node::{FilterNode, FilterServiceConfig};
use spacepose_geometry::Point;
use spacepose_ingest_node::{IngestNode, IngestServiceConfig};
use spacepose_messages::{
    AcquisitionResult, CloudHeader, Message, Name, Names, PoseEstimate, Topic,
};
use spacepose_runtime::{Envelope, LocalBus, Node, NodeInfo};
use spacepose_tracker::{TrackOutput, TrackingModel};
use spacepose_tracker_node::{TrackerNode, TrackerServiceConfig};
use std::time::Duration;

/// The services' configurations.
#[derive(Debug, Clone, Default)]
pub struct SuiteConfigs {
    /// Ingest's.
    pub ingest: IngestServiceConfig,
    /// The tracker's.
    pub tracker: TrackerServiceConfig,
    /// The filter's.
    pub filter: FilterServiceConfig,
}

/// What the suite answered for one frame.
#[derive(Debug, Clone)]
pub struct Answer {
    /// The estimate the tracker published.
    pub estimate: PoseEstimate,
    /// The tracker's output, when the cloud reached it.
    pub output: Option<TrackOutput>,
}

/// Ingest, tracker and filter on one in-memory bus.
pub struct DeployedSuite {
    bus: LocalBus,
    tracker: usize,
}

impl DeployedSuite {
    /// The three nodes; the tracker uses `model` (built once for every
    /// suite of an evaluation, as the service builds it from its config).
    pub fn new(configs: &SuiteConfigs, model: TrackingModel) -> Result<Self> {
        let names = Names::new("eval")?;
        let info = |name: &str| -> Result<NodeInfo> {
            Ok(NodeInfo {
                instance: Name::new(name)?,
                names: names.clone(),
                heartbeat: Duration::from_millis(500),
            })
        };
        let mut bus = LocalBus::new();
        bus.add(IngestNode::new(configs.ingest.clone(), &info("ingest")?)?);
        let t = &configs.tracker;
        let tracker = bus.add(TrackerNode::with_model(
            t.tracker.clone(),
            model,
            Name::new("tracker")?,
            t.max_points,
        )?);
        bus.add(FilterNode::new(configs.filter.clone(), &info("filter")?)?);
        Ok(DeployedSuite { bus, tracker })
    }

    /// Hands the suite an acquisition (the sensor's `truth_init`).
    pub fn acquire(&mut self, acquisition: AcquisitionResult) {
        self.bus.publish(Message::Acquisition(acquisition));
        self.bus.run();
    }

    /// One raw frame through the suite: the tracker's estimate of it.
    pub fn track(&mut self, header: CloudHeader, points: Vec<Point>) -> Result<Answer> {
        self.bus.publish_cloud(Topic::RawCloud, header, points);
        let estimate = self
            .bus
            .run()
            .into_iter()
            .find_map(|e| match e {
                Envelope::Message(Message::Pose(p)) => Some(p),
                _ => None,
            })
            .with_context(|| format!("no estimate for frame {}", header.sequence))?;
        let output = self
            .bus
            .node::<TrackerNode>(self.tracker)
            .and_then(|n| n.last_output().cloned());
        Ok(Answer { estimate, output })
    }
}
