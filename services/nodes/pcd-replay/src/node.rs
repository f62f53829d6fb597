//! The replay node: one recorded frame per slot of the frame clock, in
//! recorded order, optionally in a loop that continues the sensor clock.

use crate::config::PcdReplayConfig;
use crate::wire::cloud_header;
use spacepose_input::{FrameCursor, InputFrame, Recording};
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

/// Longest step between two recorded scan starts replayed as it was
/// recorded (s); a longer gap (a pause in the recording) takes one period.
pub const MAX_RECORDED_STEP_S: f64 = 10.0;

/// The current pass over the recording.
#[derive(Debug, Default)]
struct Pass {
    /// Scan start of the pass's first readable frame, as recorded.
    first_start: Option<f64>,
    /// Scan end of the pass's last readable frame, as recorded.
    last_end: Option<f64>,
    /// Added to every time of this pass (the passes before it).
    shift_s: f64,
}

/// Publishes a recording's frames as raw clouds.
pub struct PcdReplayNode {
    recording: Recording,
    /// The next frame of the recording (a new cursor starts a pass).
    cursor: FrameCursor,
    config: PcdReplayConfig,
    period: Duration,
    period_ns: i64,
    /// At recorded speed without a recorded period: each step is the one
    /// between the recorded scan starts.
    pace_by_scan: bool,
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
        let recording = spacepose_input::open(&config.input, &config.input_options())?;
        for w in recording.warnings() {
            warn!("{w}");
        }
        let recorded_s = recording.recorded_period_s();
        let period = config.period(recorded_s);
        let pace_by_scan = config.rate_hz == 0.0 && recorded_s.is_none();
        info!(
            period_s = period.as_secs_f64(),
            pace_by_scan,
            "replay running: {}",
            recording.describe()
        );
        Ok(PcdReplayNode {
            cursor: recording.cursor(),
            recording,
            config,
            period,
            period_ns: i64::try_from(period.as_nanos()).unwrap_or(i64::MAX),
            pace_by_scan,
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
                let sent = self.pending.take().map(|frame| {
                    self.publish(&frame, ctx);
                    frame.scan_start_s
                });
                let flow = self.read_ahead(ctx);
                if matches!(self.phase, Phase::Running { .. }) {
                    // Late slots are not caught up: the next one is a step later.
                    let step_ns = self.step_ns(sent);
                    let floor = ctx.now_ns.saturating_sub(step_ns);
                    self.phase = Phase::Running {
                        slot_ns: slot_ns.max(floor).saturating_add(step_ns),
                    };
                }
                flow
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

    /// The step to the next slot: the recorded step between the scan starts
    /// of the frame sent (`sent_start_s`) and the next one when pacing by
    /// scan, within (0, [`MAX_RECORDED_STEP_S`]]; else the period.
    fn step_ns(&self, sent_start_s: Option<f64>) -> i64 {
        let recorded = self
            .pending
            .as_ref()
            .zip(sent_start_s)
            .map(|(next, sent)| next.scan_start_s - sent)
            .filter(|s| self.pace_by_scan && *s > 0.0 && *s <= MAX_RECORDED_STEP_S);
        recorded.map_or(self.period_ns, |s| (s * 1e9).round() as i64)
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

    /// The next readable frame on the sensor clock; corrupt frames are
    /// logged, counted and skipped. `None` at the end of the recording:
    /// the last file without `loop`, or a whole pass without a readable
    /// frame.
    fn next_frame(&mut self, ctx: &mut Ctx<'_>) -> Option<InputFrame> {
        loop {
            let Some(result) = self.recording.next_frame(&mut self.cursor) else {
                self.next_pass()?;
                continue;
            };
            match result {
                Ok(mut frame) => {
                    self.note_derived_times(&frame, ctx);
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
        self.cursor = self.recording.cursor();
        Some(())
    }

    /// Frames without a time field get times derived over their scan
    /// interval: warned about on the first one, counted (health
    /// `derived_times`), and the count logged at the end of the recording.
    fn note_derived_times(&mut self, frame: &InputFrame, ctx: &mut Ctx<'_>) {
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
        ctx.counters.derived_times = self.derived_times;
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
