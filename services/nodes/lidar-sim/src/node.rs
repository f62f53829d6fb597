//! The simulated sensor: frame `k` of the scenario at its slot on the
//! frame clock, its truth before it and, with `truth_init`, the truth
//! acquisition before the first one.

use crate::checkpoint::{Checkpointer, Resume};
use crate::config::LidarSimConfig;
use crate::wire::{cloud_header, truth_acquisition, truth_msg};
use spacepose_lidar_sim::{Frame, FrameSource};
use spacepose_messages::{MAX_POINTS, Message, Name, ServiceKind, Topic};
use spacepose_runtime::{Ctx, Flow, Node, NodeInfo};
use tracing::{info, warn};

/// Where the sensor is in its run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Before the first poll: the starting frame is chosen then (frame 0,
    /// or the frame now due after a restart).
    Starting,
    /// Frame `next.frame` goes out at `next.slot_ns`.
    Running(Resume),
    /// Every frame is out; heartbeats only (`exit_at_end = false`).
    Idle,
}

/// Publishes simulated raw frames and their truth on the frame clock.
pub struct LidarSimNode {
    config: LidarSimConfig,
    source: FrameSource,
    instance: Name,
    checkpoint: Option<Checkpointer>,
    period_ns: Option<i64>,
    phase: Phase,
}

impl Node for LidarSimNode {
    const KIND: ServiceKind = ServiceKind::LidarSim;
    type Config = LidarSimConfig;

    fn new(config: LidarSimConfig, info: &NodeInfo) -> anyhow::Result<Self> {
        let source = config.frame_source()?;
        let fingerprint_text = format!("{config:?}");
        let checkpoint = config
            .checkpoint_file
            .clone()
            .map(|path| Checkpointer::new(path, &fingerprint_text, config.checkpoint_max_age_s));
        info!(
            target = config.target,
            scenario = %config.scenario,
            frames = config.frames,
            rate_hz = config.rate_hz,
            clutter = config.clutter,
            "simulated sensor ready"
        );
        Ok(LidarSimNode {
            period_ns: config.period_ns(),
            config,
            source,
            instance: info.instance,
            checkpoint,
            phase: Phase::Starting,
        })
    }

    fn poll(&mut self, ctx: &mut Ctx<'_>) -> Flow {
        match self.phase {
            Phase::Starting => {
                let start = self.starting_point(ctx);
                self.phase = Phase::Running(start);
                self.after(start.frame)
            }
            Phase::Running(next) if ctx.now_ns >= next.slot_ns => {
                self.take_slot(next, ctx);
                self.after(next.frame + 1)
            }
            Phase::Running(_) | Phase::Idle => Flow::Continue,
        }
    }

    fn next_wake_ns(&self) -> Option<i64> {
        match self.phase {
            Phase::Starting => Some(i64::MIN),
            Phase::Running(next) => Some(next.slot_ns),
            Phase::Idle => None,
        }
    }
}

impl LidarSimNode {
    /// Where the sensor is.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// The frames it publishes.
    pub fn source(&self) -> &FrameSource {
        &self.source
    }

    /// Frame 0 now, or the frame due now on the grid of the checkpoint a
    /// predecessor left. A checkpoint that cannot be read is counted.
    fn starting_point(&self, ctx: &mut Ctx<'_>) -> Resume {
        let Some(checkpoint) = &self.checkpoint else {
            return Resume::fresh(ctx.now_ns);
        };
        match checkpoint.starting_point(ctx.now_ns, self.period_ns) {
            Ok(r) => r,
            Err(e) => {
                warn!("{e:#}: starting at frame 0");
                ctx.counters.errors += 1;
                Resume::fresh(ctx.now_ns)
            }
        }
    }

    /// Frame `slot.frame` takes its slot: checkpoint, simulate, publish,
    /// and the next slot a period later (late slots are not caught up).
    fn take_slot(&mut self, slot: Resume, ctx: &mut Ctx<'_>) {
        let k = slot.frame;
        // Before publishing: a crash in between loses frame k, never
        // publishes it twice.
        if let Some(Err(e)) = self.checkpoint.as_ref().map(|c| c.record(k, ctx.now_ns)) {
            warn!(sequence = k, "{e:#}");
            ctx.counters.errors += 1;
        }
        match self.source.frame(k) {
            Ok(frame) => self.publish(&frame, k, ctx),
            Err(e) => {
                warn!("frame {k}: {e}");
                ctx.counters.errors += 1;
            }
        }
        let slot_ns = match self.period_ns {
            Some(p) => slot
                .slot_ns
                .max(ctx.now_ns.saturating_sub(p))
                .saturating_add(p),
            None => ctx.now_ns,
        };
        self.phase = Phase::Running(Resume {
            frame: k + 1,
            slot_ns,
        });
    }

    /// What follows once `next` is the next frame: more frames, or the end
    /// of a finite run (exit, or idle heartbeats).
    fn after(&mut self, next: u64) -> Flow {
        if self.config.frames == 0 || next < self.config.frames {
            return Flow::Continue;
        }
        if self.config.exit_at_end {
            return Flow::Finished;
        }
        if self.phase != Phase::Idle {
            info!("all {next} frames published; idle");
            self.phase = Phase::Idle;
        }
        Flow::Continue
    }

    /// Acquisition (first frame, `truth_init`), then the truth, then the
    /// cloud: once the cloud is out, the scorers have the frame's truth,
    /// even if the sensor dies right after (a kill between the two would
    /// otherwise leave a tracked frame without truth).
    fn publish(&self, frame: &Frame, k: u64, ctx: &mut Ctx<'_>) {
        ctx.counters.frames_in += 1;
        if k == 0 && self.config.truth_init {
            ctx.send(&Message::Acquisition(truth_acquisition(
                frame,
                self.instance,
            )));
        }
        ctx.send(&Message::Truth(truth_msg(k, &frame.truth)));
        if frame.points.len() > MAX_POINTS {
            warn!(
                sequence = k,
                "{} points exceed the capacity",
                frame.points.len()
            );
            ctx.counters.rejected_oversized += 1;
            return;
        }
        let header = cloud_header(k, frame, self.config.sensor_id);
        if ctx.send_cloud(Topic::RawCloud, header, &frame.points) {
            ctx.counters.frames_out += 1;
            ctx.counters.last_frame = k;
        }
    }
}

#[cfg(test)]
#[path = "node_tests.rs"]
mod tests;
