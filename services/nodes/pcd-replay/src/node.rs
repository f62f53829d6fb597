//! The replay node: one recorded frame per slot of the frame clock, in
//! index order, optionally in a loop that continues the sensor clock.

use crate::config::PcdReplayConfig;
use crate::wire::cloud_header;
use spacepose_input::{InputFrame, PcdDir};
use spacepose_messages::{MAX_POINTS, ServiceKind, Topic};
use spacepose_runtime::{Ctx, Flow, Node, NodeInfo};
use std::time::Duration;
use tracing::{info, warn};

/// Where the replay is in its run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Before the first poll: the frame clock starts then.
    Starting,
    /// The next frame goes out at `slot_ns` (CLOCK_REALTIME, ns).
    Running {
        /// Its slot.
        slot_ns: i64,
    },
    /// The recording is over; heartbeats only (`exit_at_end = false`).
    Idle,
}

/// The current pass over the directory.
#[derive(Debug, Default)]
struct Pass {
    /// Next file to read.
    file: usize,
    /// Scan start of the pass's first readable frame, as recorded.
    first_start: Option<f64>,
    /// Scan end of the pass's last readable frame, as recorded.
    last_end: Option<f64>,
    /// Added to every time of this pass (the passes before it).
    shift_s: f64,
}

/// Publishes a directory of recorded frames as raw clouds.
pub struct PcdReplayNode {
    dir: PcdDir,
    config: PcdReplayConfig,
    period: Duration,
    period_ns: i64,
    pass: Pass,
    /// The next frame, read ahead of its slot.
    pending: Option<InputFrame>,
    sequence: u64,
    phase: Phase,
    /// Frames read whose point times were derived (no time field).
    derived_times: u64,
}

impl Node for PcdReplayNode {
    const KIND: ServiceKind = ServiceKind::PcdReplay;
    type Config = PcdReplayConfig;

    fn new(config: PcdReplayConfig, _: &NodeInfo) -> anyhow::Result<Self> {
        let dir = PcdDir::open(&config.dir, &config.input_options())?;
        for w in dir.warnings() {
            warn!("{w}");
        }
        let period = config.period(dir.recorded_period_s());
        info!(
            frames = dir.len(),
            period_s = period.as_secs_f64(),
            dir = %config.dir.display(),
            "replay running"
        );
        Ok(PcdReplayNode {
            dir,
            config,
            period,
            period_ns: i64::try_from(period.as_nanos()).unwrap_or(i64::MAX),
            pass: Pass::default(),
            pending: None,
            sequence: 0,
            phase: Phase::Starting,
            derived_times: 0,
        })
    }

    fn poll(&mut self, ctx: &mut Ctx<'_>) -> Flow {
        match self.phase {
            Phase::Starting => {
                self.phase = Phase::Running {
                    slot_ns: ctx.now_ns,
                };
                self.read_ahead(ctx)
            }
            Phase::Running { slot_ns } if ctx.now_ns >= slot_ns => {
                if let Some(frame) = self.pending.take() {
                    self.publish(&frame, ctx);
                }
                // Late slots are not caught up: the next one is a period later.
                let floor = ctx.now_ns.saturating_sub(self.period_ns);
                self.phase = Phase::Running {
                    slot_ns: slot_ns.max(floor).saturating_add(self.period_ns),
                };
                self.read_ahead(ctx)
            }
            Phase::Running { .. } | Phase::Idle => Flow::Continue,
        }
    }

    fn next_wake_ns(&self) -> Option<i64> {
        match self.phase {
            Phase::Starting => Some(i64::MIN),
            Phase::Running { slot_ns } => Some(slot_ns),
            Phase::Idle => None,
        }
    }
}

impl PcdReplayNode {
    /// Where the replay is.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// The frame period.
    pub fn period(&self) -> Duration {
        self.period
    }

    /// Reads the next frame for its slot; at the end of the recording,
    /// exits or idles.
    fn read_ahead(&mut self, ctx: &mut Ctx<'_>) -> Flow {
        self.pending = self.next_frame(ctx);
        if self.pending.is_some() {
            return Flow::Continue;
        }
        if self.config.exit_at_end {
            return Flow::Finished;
        }
        info!(
            derived_times = self.derived_times,
            "end of the recording; idle"
        );
        self.phase = Phase::Idle;
        Flow::Continue
    }

    /// The next readable frame on the sensor clock; corrupt files are
    /// logged, counted and skipped. `None` at the end of the recording:
    /// the last file without `loop`, or a whole pass without a readable
    /// frame.
    fn next_frame(&mut self, ctx: &mut Ctx<'_>) -> Option<InputFrame> {
        loop {
            let Some(result) = self.dir.read(self.pass.file) else {
                self.next_pass()?;
                continue;
            };
            self.pass.file += 1;
            match result {
                Ok(mut frame) => {
                    self.note_derived_times(&frame);
                    self.pass.first_start.get_or_insert(frame.scan_start_s);
                    self.pass.last_end = Some(frame.scan_end_s);
                    frame.shift_time(self.pass.shift_s);
                    return Some(frame);
                }
                Err(e) => {
                    warn!("skipped: {e}");
                    ctx.counters.errors += 1;
                }
            }
        }
    }

    /// Starts the next pass, one period after the end of this one; `None`
    /// without `loop` or after a pass without a readable frame.
    fn next_pass(&mut self) -> Option<()> {
        if !self.config.looping {
            return None;
        }
        let (Some(a), Some(b)) = (self.pass.first_start, self.pass.last_end) else {
            warn!("no readable frame in a whole pass: end of the replay");
            return None;
        };
        self.pass = Pass {
            shift_s: self.pass.shift_s + ((b - a) + self.period.as_secs_f64()),
            ..Pass::default()
        };
        Some(())
    }

    /// Frames without a time field get times derived over their scan
    /// interval: warned about on the first one, counted, and the count
    /// logged at the end of the recording.
    fn note_derived_times(&mut self, frame: &InputFrame) {
        if !frame.times_derived() {
            return;
        }
        if self.derived_times == 0 {
            warn!(
                frame = %frame.origin,
                "no per-point time field: times derived linearly over the scan interval \
                 [{}, {}] s in point order (set [time] field in the config if the files have one)",
                frame.scan_start_s, frame.scan_end_s
            );
        }
        self.derived_times += 1;
    }

    /// Frames read so far whose point times were derived.
    pub fn derived_times(&self) -> u64 {
        self.derived_times
    }

    fn publish(&mut self, frame: &InputFrame, ctx: &mut Ctx<'_>) {
        ctx.counters.frames_in += 1;
        let header = cloud_header(self.sequence, frame, self.config.sensor_id);
        self.sequence += 1;
        if frame.points.len() > MAX_POINTS {
            warn!(frame = %frame.origin, "{} points exceed the capacity", frame.points.len());
            ctx.counters.rejected_oversized += 1;
            return;
        }
        if ctx.send_cloud(Topic::RawCloud, header, &frame.points) {
            ctx.counters.frames_out += 1;
            ctx.counters.last_frame = header.sequence;
        }
    }
}

#[cfg(test)]
#[path = "node_tests.rs"]
mod tests;
