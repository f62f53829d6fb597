//! `spacepose demo`: bring up `deploy/demo.toml`, follow N frames through
//! the real processes, score the poses against the simulator's truth, print
//! a table like seed 000 Table 3, bring everything down.
//!
//! Truth only scores: the demo (like telemetry) is a scorer and subscribes
//! to `truth`; no estimator sees it.

pub mod chaos;
pub mod report;
pub mod score;
pub mod target;

use super::descriptor::Descriptor;
use super::supervisor::Supervisor;
use super::up::{Overrides, bring_up, plan_descriptor};
use anyhow::{Context, Result, bail};
use chaos::{Action, ChaosSpec, Injection, SwapSpec};
use score::{Scorer, Summary};
use spacepose_bus::{Bus, CloudSubscriber, Subscriber, WakeReason};
use spacepose_messages::ServiceKind;
use spacepose_messages::{FilterState, Names, PoseEstimate, TruthMsg, realtime_ns};
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
    /// The sensor's seed, replacing the descriptor's.
    pub seed: Option<u64>,
    /// The target that replaces the descriptor's.
    pub target: Option<target::TargetOverride>,
    /// Frames excluded from the converged figures.
    pub warmup: usize,
    /// Where to write the JSON summary.
    pub json: Option<PathBuf>,
    /// Prefix, zenoh endpoints.
    pub overrides: Overrides,
    /// How long to wait for a missing pose after the last frame.
    pub linger: Duration,
    /// Faults to inject.
    pub chaos: Vec<ChaosSpec>,
    /// A swap of the primary tracker during the run.
    pub swap: Option<SwapSpec>,
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

/// The descriptor with the demo's overrides: prefix, zenoh endpoints,
/// every sensor's frame count and seed, and the target.
fn demo_descriptor(opts: &DemoOptions) -> Result<Descriptor> {
    let mut d = Descriptor::load(&opts.deploy)?;
    if let Some(target) = &opts.target {
        let range_scale = target.apply(&mut d);
        tracing::info!(
            "target {} (bounding radius {:.2} m): the sensor's legs at {range_scale:.2} x seed 000's",
            target.spec,
            target.bounding_radius_m,
        );
    }
    let mut overrides = opts.overrides.clone();
    overrides.prefix.get_or_insert_with(fresh_prefix);
    overrides.apply(&mut d);
    let frames = i64::try_from(opts.frames).context("--frames is too large")?;
    let mut sensors = 0;
    for s in d.instances_of_mut(ServiceKind::LidarSim) {
        s.config
            .insert("frames".into(), toml::Value::Integer(frames));
        if let Some(seed) = opts.seed {
            let seed = i64::try_from(seed).context("--seed is too large")?;
            s.config.insert("seed".into(), toml::Value::Integer(seed));
        }
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

/// The symmetry group of the sensor's target, for scoring with `d_sym`:
/// the group its package records (built-in, package directory or mesh
/// file, resolved as lidar-sim resolves it); none when the target cannot
/// be resolved (lidar-sim's own `--check` reports that).
fn target_symmetries(d: &Descriptor) -> Vec<nalgebra::Rotation3<f64>> {
    let config = d
        .instances_of(ServiceKind::LidarSim)
        .next()
        .map(|s| &s.config);
    let get = |key: &str| config.and_then(|c| c.get(key));
    let name = get("target")
        .and_then(toml::Value::as_str)
        .unwrap_or("deos");
    let scale = get("scale").and_then(toml::Value::as_float).unwrap_or(1.0);
    spacepose_prepare::resolve(name, scale)
        .map(|p| p.target.symmetries().to_vec())
        .unwrap_or_default()
}

struct Ports {
    poses: Subscriber<PoseEstimate>,
    truth: Subscriber<TruthMsg>,
    states: Subscriber<FilterState>,
    raw: CloudSubscriber,
}

impl Ports {
    fn open(bus: &Bus, names: &Names) -> Result<Self> {
        Ok(Self {
            poses: bus.subscriber(&names.pose())?,
            truth: bus.subscriber(&names.truth())?,
            states: bus.subscriber(&names.filter_state())?,
            raw: bus.cloud_subscriber(&names.raw_cloud())?,
        })
    }

    /// Drains every port; returns whether a truth arrived and the newest
    /// raw frame published.
    fn drain(
        &self,
        scorer: &mut Scorer,
        out: &mut dyn Write,
        start: Instant,
    ) -> Result<(bool, Option<u64>)> {
        let mut truth_seen = false;
        let mut newest_raw = None;
        while let Some(c) = self.raw.try_recv()? {
            newest_raw = newest_raw.max(Some(c.header().sequence));
            scorer.on_raw_cloud(c.header().sequence, c.header().published_ns);
        }
        while let Some(s) = self.states.try_recv()? {
            scorer.on_state(&s);
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
        Ok((truth_seen, newest_raw))
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
    let (up_bus, watch, suite) =
        bring_up(&plan, "demo-up", out).context("the demo suite failed to start")?;
    let mut sup = Supervisor::new(plan, up_bus, watch, suite)?;
    writeln!(out, "{}", report::live_header())?;
    let mut injections: Vec<Injection> = opts
        .chaos
        .iter()
        .map(|c| Injection {
            spec: c.clone(),
            at: None,
            at_ns: 0,
        })
        .collect();
    // The group of the package resolved for --target, else the descriptor's.
    let symmetries = opts
        .target
        .as_ref()
        .map_or_else(|| target_symmetries(&d), |t| t.symmetries.clone());
    let scorer = Scorer::with_symmetries(symmetries);
    let followed = follow(opts, &bus, &ports, &mut sup, &mut injections, scorer, out);
    // Frozen processes cannot stop: thaw them first.
    for i in injections.iter().filter(|i| i.spec.action == Action::Stop) {
        sup.suite
            .signal(&i.spec.instance, rustix::process::Signal::CONT);
    }
    let _ = sup.watch.drain();
    let _ = sup.save_state();
    let health = super::status::render(&sup.suite.state, &sup.watch);
    let restarts = sup
        .suite
        .state
        .instances
        .iter()
        .map(|i| (i.name.clone(), i.restarts))
        .collect();
    let faults = sup.faults.clone();
    let swap = sup.swaps.last().cloned();
    drop(ports);
    drop(bus);
    let stopped = sup.stop(out);
    let scorer = followed?;
    stopped?;
    writeln!(out, "suite {:?} stopped", names.prefix())?;
    let mut summary = Summary::new(names.prefix(), &scorer, opts.frames, opts.warmup);
    let fusions = scorer.fusions();
    summary.chaos = injections
        .iter()
        .map(|i| i.report(&faults, &fusions))
        .collect();
    summary.swap = swap;
    summary.restarts = restarts;
    writeln!(out, "\nhealth at the end of the run:\n{health}")?;
    write!(out, "{}", report::final_table(&summary))?;
    write!(out, "{}", report::chaos_lines(&summary))?;
    if let Some(path) = &opts.json {
        write_json(path, &summary)?;
        writeln!(out, "summary written to {}", path.display())?;
    }
    Ok(summary)
}

/// How long the demo keeps listening once every frame has a pose.
const SETTLE: Duration = Duration::from_millis(300);

/// Follows the run until every frame has a pose, or the sensor has stopped
/// for `linger`, or a service failed for good. The supervisor runs every
/// few milliseconds in between; faults and the swap are injected on time.
fn follow(
    opts: &DemoOptions,
    bus: &Bus,
    ports: &Ports,
    sup: &mut Supervisor,
    injections: &mut [Injection],
    mut scorer: Scorer,
    out: &mut dyn Write,
) -> Result<Scorer> {
    let mut waiter = bus.waitset()?;
    waiter.attach(&ports.poses)?;
    waiter.attach(&ports.truth)?;
    waiter.attach(&ports.raw)?;
    let start = Instant::now();
    let mut last_truth = Instant::now();
    let mut newest_raw: Option<u64> = None;
    let mut swap = opts.swap.clone();
    let mut done_at: Option<Instant> = None;
    // Generous: the first frame waits for the map and the acquisition.
    let first_frame_timeout = Duration::from_secs(60);
    loop {
        if waiter.wait(Duration::from_millis(5))? == WakeReason::TerminationRequested {
            bail!("interrupted");
        }
        let (truth, raw) = ports.drain(&mut scorer, out, start)?;
        if truth {
            last_truth = Instant::now();
        }
        newest_raw = newest_raw.max(raw);
        inject(sup, injections, newest_raw, out)?;
        if let Some(s) = swap
            .as_ref()
            .filter(|s| newest_raw.is_some_and(|r| r >= s.at_frame))
        {
            let req = super::swap::SwapRequest {
                kind: ServiceKind::Tracker,
                mode: Some(s.mode.clone()),
                binary: None,
            };
            writeln!(out, "swap: tracker -> {} at frame {}", s.mode, s.at_frame)?;
            sup.request_swap(req, out)?;
            swap = None;
        }
        sup.step(out)?;
        // Every frame produced: all of them, or up to the last one (a
        // restarted sensor does not replay the frames it missed).
        let produced = scorer.truths() as u64 >= opts.frames
            || scorer.newest_truth().is_some_and(|k| k + 1 >= opts.frames);
        let done = produced
            && scorer.scored().len() + scorer.unscorable as usize >= scorer.truths()
            && !sup.swapping();
        // Once every frame has a pose, wait a little for the filter states
        // of the last frames (the filter may wait up to its frame deadline).
        match (done, done_at) {
            (true, None) => done_at = Some(Instant::now()),
            (true, Some(t)) if t.elapsed() >= SETTLE => return Ok(scorer),
            (false, _) => done_at = None,
            _ => {}
        }
        let quiet = last_truth.elapsed();
        if (scorer.truths() > 0 && quiet > opts.linger && !sup.swapping())
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
        check_failed(sup)?;
    }
}

/// Injects the faults whose frame has been published.
fn inject(
    sup: &Supervisor,
    injections: &mut [Injection],
    newest_raw: Option<u64>,
    out: &mut dyn Write,
) -> Result<()> {
    let Some(raw) = newest_raw else {
        return Ok(());
    };
    for i in injections
        .iter_mut()
        .filter(|i| i.at.is_none() && raw >= i.spec.at_frame)
    {
        let Some(pid) = sup.suite.pid(&i.spec.instance) else {
            bail!("--chaos: no instance {:?} in the suite", i.spec.instance);
        };
        let signal = match i.spec.action {
            Action::Kill => rustix::process::Signal::KILL,
            Action::Stop => rustix::process::Signal::STOP,
        };
        super::process::signal_group(pid, signal);
        i.at = Some(Instant::now());
        i.at_ns = realtime_ns();
        writeln!(
            out,
            "chaos: {:?} {} (pid {pid}) after frame {raw}",
            i.spec.action, i.spec.instance
        )?;
    }
    Ok(())
}

/// Fails when an instance is down for good (a finished sensor may exit).
pub(crate) fn check_failed(sup: &Supervisor) -> Result<()> {
    for i in &sup.suite.state.instances {
        if i.status == "failed" {
            bail!(
                "service {:?} failed and is not restarted; last lines of {}:\n{}",
                i.name,
                i.log.display(),
                super::process::log_tail(&i.log, 15)
            );
        }
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
