//! Runs the replay suite until every recorded frame has gone out and its
//! poses have come back (or stopped coming), collecting what it publishes.

use super::recorded::RecordedRun;
use crate::suite::demo::check_failed;
use crate::suite::plan::Plan;
use crate::suite::supervisor::Supervisor;
use crate::suite::up::bring_up;
use anyhow::{Context, Result, bail};
use spacepose_bus::{Bus, CloudSubscriber, Subscriber, WakeReason};
use spacepose_foxglove::AcquisitionRecord;
use spacepose_messages::telemetry::TelemetryPose;
use spacepose_messages::{AcquisitionResult, PoseEstimate};
use std::collections::BTreeSet;
use std::io::Write;
use std::time::{Duration, Instant};

/// What the replayed suite published, in its own frame numbering.
#[derive(Debug, Default)]
pub struct Replayed {
    /// Every pose.
    pub poses: Vec<TelemetryPose>,
    /// Every acquisition.
    pub acquisitions: Vec<AcquisitionRecord>,
    /// Raw clouds published by the replay.
    pub raw_clouds: usize,
    /// Messages that could not be converted (counted, skipped).
    pub refused: usize,
}

/// How long to wait for the first frame (the tracker builds its map first).
const FIRST_FRAME_TIMEOUT: Duration = Duration::from_secs(60);
/// How long to keep listening once every frame has its poses.
const SETTLE: Duration = Duration::from_millis(300);

struct Ports {
    poses: Subscriber<PoseEstimate>,
    acquisitions: Subscriber<AcquisitionResult>,
    raw: CloudSubscriber,
}

impl Ports {
    /// Drains every port into `r`; true when anything arrived.
    fn drain(&self, r: &mut Replayed) -> Result<bool> {
        let before = (r.raw_clouds, r.poses.len(), r.acquisitions.len(), r.refused);
        while self.raw.try_recv()?.is_some() {
            r.raw_clouds += 1;
        }
        while let Some(p) = self.poses.try_recv()? {
            match TelemetryPose::from_wire(&p) {
                Ok(p) => r.poses.push(p),
                Err(_) => r.refused += 1,
            }
        }
        while let Some(a) = self.acquisitions.try_recv()? {
            match AcquisitionRecord::from_wire(&a) {
                Ok(a) => r.acquisitions.push(a),
                Err(_) => r.refused += 1,
            }
        }
        Ok(before != (r.raw_clouds, r.poses.len(), r.acquisitions.len(), r.refused))
    }
}

/// True when every tracker of the recording (`instances`) has a pose of
/// the frame `last` or later.
fn last_frame_posed(r: &Replayed, instances: &BTreeSet<&str>, last: u64) -> bool {
    instances.iter().all(|i| {
        r.poses
            .iter()
            .rev()
            .any(|p| p.instance == *i && p.sequence >= last)
    })
}

/// Starts `plan`, follows it, stops it.
///
/// # Errors
/// The suite fails to start, a service fails for good, or no frame comes.
pub fn run(
    plan: Plan,
    recorded: &RecordedRun,
    linger: Duration,
    out: &mut dyn Write,
) -> Result<Replayed> {
    let names = plan.names.clone();
    let bus = Bus::open(&names, &format!("sp-replay-{}", std::process::id()))?;
    let ports = Ports {
        poses: bus.subscriber(&names.pose())?,
        acquisitions: bus.subscriber(&names.acquisition())?,
        raw: bus.cloud_subscriber(&names.raw_cloud())?,
    };
    let (up_bus, watch, suite) =
        bring_up(&plan, "replay-up", out).context("the replay suite failed to start")?;
    let mut sup = Supervisor::new(plan, up_bus, watch, suite)?;
    let followed = follow(&bus, &ports, &mut sup, recorded, linger, out);
    drop(ports);
    drop(bus);
    let stopped = sup.stop(out);
    let replayed = followed?;
    stopped?;
    writeln!(out, "suite {:?} stopped", names.prefix())?;
    Ok(replayed)
}

fn follow(
    bus: &Bus,
    ports: &Ports,
    sup: &mut Supervisor,
    recorded: &RecordedRun,
    linger: Duration,
    out: &mut dyn Write,
) -> Result<Replayed> {
    let mut waiter = bus.waitset()?;
    waiter.attach(&ports.poses)?;
    waiter.attach(&ports.raw)?;
    let mut r = Replayed::default();
    let total = recorded.raw_sequences.len();
    let last = total.saturating_sub(1) as u64;
    let instances: BTreeSet<&str> = recorded.poses.iter().map(|p| p.instance.as_str()).collect();
    let start = Instant::now();
    let mut last_news = Instant::now();
    let mut done_at: Option<Instant> = None;
    loop {
        if waiter.wait(Duration::from_millis(5))? == WakeReason::TerminationRequested {
            bail!("interrupted");
        }
        let shown = r.raw_clouds;
        if ports.drain(&mut r)? {
            last_news = Instant::now();
        }
        if r.raw_clouds / 10 > shown / 10 || (r.raw_clouds == total && shown < total) {
            writeln!(
                out,
                "{:>7.1} s  frame {}/{total}, {} poses",
                start.elapsed().as_secs_f64(),
                r.raw_clouds,
                r.poses.len()
            )?;
        }
        sup.step(out)?;
        let all_out = r.raw_clouds >= total;
        match (all_out && last_frame_posed(&r, &instances, last), done_at) {
            (true, None) => done_at = Some(Instant::now()),
            (true, Some(t)) if t.elapsed() >= SETTLE => return Ok(r),
            (false, _) => done_at = None,
            _ => {}
        }
        let quiet = last_news.elapsed();
        if (all_out && quiet > linger) || (r.raw_clouds == 0 && quiet > FIRST_FRAME_TIMEOUT) {
            writeln!(
                out,
                "nothing new for {:.1} s: ending the replay",
                quiet.as_secs_f64()
            )?;
            return Ok(r);
        }
        check_failed(sup)?;
    }
}
