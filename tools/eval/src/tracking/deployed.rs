//! The suite in one process: the deployed ingest, tracker and filter nodes
//! wired by the topic graph on a [`LocalBus`], fed the raw frames and
//! either the truth acquisition the simulated sensor publishes or, with
//! [`DeployedSuite::with_init`], the init service's own acquisitions from
//! the frames (no truth at all). Every message crosses the same
//! conversions as between the processes, so a frame is cropped,
//! motion-compensated, voxel-filtered, registered and fused exactly as in
//! the suite (the end-to-end test `frame_path` checks it against the real
//! processes).
//!
//! Acquisition in lockstep. In the suite, init acquires on its own thread
//! while frames go on, and its result reaches the tracker some frames
//! later, depending on the machine's speed. Here each frame waits for an
//! acquisition it started, so the result applies from the next frame on
//! whatever the machine: the same frames give the same poses (issue 26's
//! bit-identical offline tracking). The cost is that the acquisition's
//! latency is not simulated; its compute time is in every result.

use anyhow::{Context, Result};
use spacepose_filter_node::{FilterNode, FilterServiceConfig};
use spacepose_geometry::Point;
use spacepose_ingest_node::{IngestNode, IngestServiceConfig};
use spacepose_init_node::{InitNode, InitServiceConfig};
use spacepose_messages::{
    AcquisitionResult, CloudHeader, FilterState, Message, Name, Names, PoseEstimate, Topic,
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
    /// Acquisitions init published on this frame (accepted or not), with
    /// [`DeployedSuite::with_init`]; they apply from the next frame on.
    /// Init's records that confirm an earlier acquisition are not among
    /// them (they are in `sent`).
    pub acquisitions: Vec<AcquisitionResult>,
    /// The filter service's state after the frame, when initialised: the
    /// posterior the tracker's next prediction starts from.
    pub filter_state: Option<FilterState>,
    /// Everything the nodes published for this frame, in order (the
    /// cropped cloud, the estimate, the filter state, acquisitions), for a
    /// recording.
    pub sent: Vec<Envelope>,
}

/// Ingest, tracker and filter (and init) on one in-memory bus.
pub struct DeployedSuite {
    bus: LocalBus,
    tracker: usize,
    filter: usize,
    init: Option<usize>,
}

/// How often a frame looks whether init's acquisition has finished.
const ACQUISITION_POLL: Duration = Duration::from_millis(2);

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
        let filter = bus.add(FilterNode::new(configs.filter.clone(), &info("filter")?)?);
        Ok(DeployedSuite {
            bus,
            tracker,
            filter,
            init: None,
        })
    }

    /// The suite with the init service acquiring from the frames (its
    /// method chain built from `init`, as the service builds it): no truth
    /// reaches it.
    pub fn with_init(
        configs: &SuiteConfigs,
        model: TrackingModel,
        init: InitServiceConfig,
    ) -> Result<Self> {
        let mut suite = Self::new(configs, model)?;
        let info = NodeInfo {
            instance: Name::new("init")?,
            names: Names::new("eval")?,
            heartbeat: Duration::from_millis(500),
        };
        let node = InitNode::new(init, &info).context("the init service")?;
        suite.init = Some(suite.bus.add(node));
        Ok(suite)
    }

    /// Hands the suite an acquisition (the sensor's `truth_init`).
    pub fn acquire(&mut self, acquisition: AcquisitionResult) {
        self.bus.publish(Message::Acquisition(acquisition));
        self.bus.run();
    }

    /// One raw frame through the suite: the tracker's estimate of it.
    pub fn track(&mut self, header: CloudHeader, points: Vec<Point>) -> Result<Answer> {
        self.bus.publish_cloud(Topic::RawCloud, header, points);
        let mut sent = self.bus.run();
        let estimate = sent
            .iter()
            .find_map(|e| match e {
                Envelope::Message(Message::Pose(p)) => Some(*p),
                _ => None,
            })
            .with_context(|| format!("no estimate for frame {}", header.sequence))?;
        let output = self
            .bus
            .node::<TrackerNode>(self.tracker)
            .and_then(|n| n.last_output().cloned());
        let filter_state = self
            .bus
            .node::<FilterNode>(self.filter)
            .map(FilterNode::filter_state)
            .filter(|s| s.initialized != 0);
        sent.extend(self.finish_acquisition());
        let acquisitions = sent
            .iter()
            .filter_map(|e| match e {
                Envelope::Message(Message::Acquisition(a)) if a.confirms().is_none() => Some(*a),
                _ => None,
            })
            .collect();
        Ok(Answer {
            estimate,
            output,
            acquisitions,
            filter_state,
            sent,
        })
    }

    /// Waits for the acquisition init started on this frame, if any, and
    /// delivers its result (lockstep: see the module's documentation).
    fn finish_acquisition(&mut self) -> Vec<Envelope> {
        let Some(init) = self.init else {
            return Vec::new();
        };
        let mut sent = Vec::new();
        while self.bus.node::<InitNode>(init).is_some_and(InitNode::busy) {
            std::thread::sleep(ACQUISITION_POLL);
            sent.extend(self.bus.poll());
        }
        sent
    }
}
