//! `spacepose demo`: bring up `deploy/demo.toml`, follow N frames through
//! the real processes, score the poses against the simulator's truth, print
//! a table like seed 000 Table 3, bring everything down.
//!
//! Truth only scores: the demo (like telemetry) is a scorer and subscribes
//! to `truth`; no estimator sees it.

pub mod report;
pub mod score;

use super::descriptor::Descriptor;
use super::kind::ServiceKind;
use super::launch::RunningSuite;
use super::up::{Overrides, bring_up, plan_descriptor};
use anyhow::{Context, Result, bail};
use score::{Scorer, Summary};
use spacepose_bus::{Bus, CloudSubscriber, Subscriber, WakeReason};
use spacepose_messages::{Names, PoseEstimate, TruthMsg};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Options of a demo run.
#[derive(Debug, Clone)]
pub struct DemoOptions {
    /// Descriptor file.
    pub deploy: PathBuf,
    /// Frames to run.
    pub frames: u64,
    /// Frames excluded from the converged figures.
    pub warmup: usize,
    /// Where to write the JSON summary.
    pub json: Option<PathBuf>,
    /// Prefix, zenoh endpoints.
    pub overrides: Overrides,
    /// How long to wait for a missing pose after the last frame.
    pub linger: Duration,
}

/// A fresh prefix (`demo-` and 8 hex digits from the pid and the clock),
/// so two demos on one machine never meet.
pub fn fresh_prefix() -> String {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    // FNV-1a over pid and time: a name, not a random draw.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in u64::from(std::process::id())
        .to_le_bytes()
        .into_iter()
        .chain(nanos.to_le_bytes())
    {
        h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
    }
    format!("demo-{:08x}", h as u32)
}

/// The descriptor with the demo's overrides: prefix, zenoh endpoints, and
/// every sensor's frame count.
fn demo_descriptor(opts: &DemoOptions) -> Result<Descriptor> {
    let mut d = Descriptor::load(&opts.deploy)?;
    let mut overrides = opts.overrides.clone();
    overrides.prefix.get_or_insert_with(fresh_prefix);
    overrides.apply(&mut d);
    let frames = i64::try_from(opts.frames).context("--frames is too large")?;
    let mut sensors = 0;
    for s in d.instances_of_mut(ServiceKind::LidarSim) {
        s.config
            .insert("frames".into(), toml::Value::Integer(frames));
        sensors += 1;
    }
    if sensors != 1 {
        bail!(
            "{}: the demo needs exactly one lidar-sim service (found {sensors})",
            opts.deploy.display()
        );
    }
    Ok(d)
}

struct Ports {
    poses: Subscriber<PoseEstimate>,
    truth: Subscriber<TruthMsg>,
    raw: CloudSubscriber,
}

impl Ports {
    fn open(bus: &Bus, names: &Names) -> Result<Self> {
        Ok(Self {
            poses: bus.subscriber(&names.pose())?,
            truth: bus.subscriber(&names.truth())?,
            raw: bus.cloud_subscriber(&names.raw_cloud())?,
        })
    }

    fn drain(&self, scorer: &mut Scorer, out: &mut dyn Write, start: Instant) -> Result<bool> {
        let mut truth_seen = false;
        while let Some(c) = self.raw.try_recv()? {
            scorer.on_raw_cloud(c.header().sequence, c.header().published_ns);
        }
        let mut scored = Vec::new();
        while let Some(t) = self.truth.try_recv()? {
            truth_seen = true;
            scored.extend(scorer.on_truth(t));
        }
        while let Some(p) = self.poses.try_recv()? {
            scored.extend(scorer.on_pose(p));
        }
        for f in scored {
            writeln!(out, "{}", report::live_line(&f, start.elapsed()))?;
        }
        Ok(truth_seen)
    }
}

/// Runs the demo; progress and the table go to `out`.
pub fn run(opts: &DemoOptions, out: &mut dyn Write) -> Result<Summary> {
    let d = demo_descriptor(opts)?;
    let plan = plan_descriptor(&d, &opts.deploy)?;
    let names = plan.names.clone();
    writeln!(
        out,
        "demo {:?}: {} frames, {} services, zenoh on {}",
        names.prefix(),
        opts.frames,
        plan.instances.len(),
        plan.zenoh.listen.join(", ")
    )?;
    // Subscribe before anything starts, so no frame is missed.
    let bus = Bus::open(&names, &format!("spacepose-demo-{}", std::process::id()))?;
    let ports = Ports::open(&bus, &names)?;
    let (up_bus, mut watch, mut suite) =
        bring_up(&plan, "demo-up", out).context("the demo suite failed to start")?;
    writeln!(out, "{}", report::live_header())?;
    let followed = follow(opts, &bus, &ports, &mut suite, out);
    let _ = watch.drain();
    let health = super::status::render(&suite.state, &watch);
    drop(watch);
    drop(up_bus);
    drop(ports);
    drop(bus);
    let stopped = suite.stop(out);
    let scorer = followed?;
    stopped?;
    writeln!(out, "suite {:?} stopped", names.prefix())?;
    let summary = Summary::new(names.prefix(), &scorer, opts.frames, opts.warmup);
    writeln!(out, "\nhealth at the end of the run:\n{health}")?;
    write!(out, "{}", report::final_table(&summary))?;
    if let Some(path) = &opts.json {
        write_json(path, &summary)?;
        writeln!(out, "summary written to {}", path.display())?;
    }
    Ok(summary)
}

/// Follows the run until every frame has a pose, or the sensor has stopped
/// for `linger`, or a service died.
fn follow(
    opts: &DemoOptions,
    bus: &Bus,
    ports: &Ports,
    suite: &mut RunningSuite,
    out: &mut dyn Write,
) -> Result<Scorer> {
    let mut waiter = bus.waitset()?;
    waiter.attach(&ports.poses)?;
    waiter.attach(&ports.truth)?;
    waiter.attach(&ports.raw)?;
    let mut scorer = Scorer::default();
    let start = Instant::now();
    let mut last_truth = Instant::now();
    // Generous: the first frame waits for the map and the acquisition.
    let first_frame_timeout = Duration::from_secs(60);
    loop {
        if waiter.wait(Duration::from_millis(200))? == WakeReason::TerminationRequested {
            bail!("interrupted");
        }
        if ports.drain(&mut scorer, out, start)? {
            last_truth = Instant::now();
        }
        let done = scorer.truths() as u64 >= opts.frames
            && scorer.scored().len() + scorer.unscorable as usize >= scorer.truths();
        if done {
            return Ok(scorer);
        }
        let quiet = last_truth.elapsed();
        if (scorer.truths() > 0 && quiet > opts.linger)
            || (scorer.truths() == 0 && quiet > first_frame_timeout)
        {
            writeln!(
                out,
                "no new frame for {:.1} s: ending the run ({} frames, {} poses)",
                quiet.as_secs_f64(),
                scorer.truths(),
                scorer.scored().len()
            )?;
            return Ok(scorer);
        }
        check_processes(suite)?;
    }
}

/// Fails when a non-source instance exited (a finished sensor may exit).
fn check_processes(suite: &mut RunningSuite) -> Result<()> {
    for (name, status) in suite.exited() {
        let kind = suite
            .state
            .instances
            .iter()
            .find(|i| i.name == name)
            .map(|i| i.kind);
        if kind.is_some_and(ServiceKind::is_source) && status.contains("exit status: 0") {
            continue;
        }
        let log = suite.log(&name).unwrap_or_default();
        bail!(
            "service {name:?} exited during the run ({status}); last lines of {}:\n{}",
            log.display(),
            super::process::log_tail(&log, 15)
        );
    }
    Ok(())
}

fn write_json(path: &Path, summary: &Summary) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    let json = serde_json::to_string_pretty(summary)?;
    std::fs::write(path, json).with_context(|| format!("cannot write {}", path.display()))
}
