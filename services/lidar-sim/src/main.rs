//! `spacepose-lidar-sim`: the sensor-driver stand-in. Publishes simulated raw
//! frames (clutter on by default) at the sensor rate, the ground truth of each
//! frame on the truth topic, and, with `truth_init = true`, one
//! `AcquisitionResult { method: truth }` for the first frame (published
//! before that frame) — the documented exception until the init service
//! exists (issue 5).
//!
//! A restarted instance continues the scenario where the dead one stopped:
//! it resumes at the frame now due from the checkpoint its predecessor
//! left (`checkpoint_file`, see [`checkpoint`] for why a checkpoint rather
//! than a shared start instant); the frames missed meanwhile are missing.

mod checkpoint;

use anyhow::{Context, Result};
use checkpoint::{Checkpoint, Resume};
use clap::Parser;
use serde::Deserialize;
use spacepose_bus::{Bus, CloudPublisher, Publisher};
use spacepose_lidar_sim::{Frame, LidarSimulator, SensorConfig};
use spacepose_messages::convert::{pose_to_wire, vector3_to_wire};
use spacepose_messages::{
    AcquisitionMethod, AcquisitionResult, CloudHeader, MAX_POINTS, Name, Names, ServiceState,
    TruthMsg, realtime_ns,
};
use spacepose_scenario::{LookAway, Scenario, ScenarioConfig, ScenarioKind, TruthState};
use spacepose_service_kit::{
    Counters, HealthReporter, ServiceArgs, ServiceConfig, init_logging, load_config, shutdown_flag,
};
use spacepose_target::Target;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};
use tracing::{error, info, warn};

const SERVICE: &str = "lidar-sim";

/// Simulator settings.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct Config {
    /// Built-in target name or mesh file path.
    target: String,
    /// Scale of the target coordinates.
    scale: f64,
    /// Relative-motion scenario.
    scenario: ScenarioKind,
    /// Seed of the scenario and of every frame's random stream.
    seed: u64,
    /// Time compression of the chaser trajectory (>= 1).
    compression: f64,
    /// Range of the random scenario (m).
    range_m: f64,
    /// Frames to publish; 0 = endless (the scenario restarts after its
    /// natural length, the sensor clock keeps running).
    frames: u64,
    /// Integration time of one frame (s).
    integration_time_s: f64,
    /// Frames per second; 0 = as fast as the simulator goes.
    rate_hz: f64,
    /// Test-facility background (floor, back wall, robot arm).
    clutter: bool,
    /// Publish an acquisition result from the truth for the first frame.
    truth_init: bool,
    /// After the last frame (frames > 0): exit, or stay up sending heartbeats.
    exit_at_end: bool,
    /// Sensor id written in the cloud headers.
    sensor_id: u16,
    /// Frames during which the sensor looks away from the target (e.g.
    /// `look_away = { first_frame = 8, frames = 4, angle_deg = 60.0 }`): the
    /// loss-and-reacquisition variant. Absent = never.
    look_away: Option<LookAway>,
    /// File recording the last frame slot taken (written before each
    /// frame); a restarted sensor resumes from it at the frame now due.
    /// `spacepose up` sets `{run dir}/{instance}.sensorstate`. None: every
    /// start begins at frame 0.
    checkpoint_file: Option<PathBuf>,
    /// A checkpoint older than this (s, wall clock) is ignored.
    checkpoint_max_age_s: f64,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            target: "deos".into(),
            scale: 1.0,
            scenario: ScenarioKind::Tumbling,
            seed: 0,
            compression: 1.0,
            range_m: 20.0,
            frames: 0,
            integration_time_s: SensorConfig::MID40_INTEGRATION_TIME_S,
            rate_hz: 1.0,
            clutter: true,
            truth_init: false,
            exit_at_end: false,
            sensor_id: 0,
            look_away: None,
            checkpoint_file: None,
            checkpoint_max_age_s: 60.0,
        }
    }
}

impl ServiceConfig for Config {
    fn validate(&self) -> Result<(), String> {
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!("{name} must be finite and > 0, got {v}"))
            }
        };
        positive("scale", self.scale)?;
        positive("range_m", self.range_m)?;
        positive("integration_time_s", self.integration_time_s)?;
        positive("checkpoint_max_age_s", self.checkpoint_max_age_s)?;
        if let Some(look) = &self.look_away {
            look.validate().map_err(|e| e.to_string())?;
        }
        if !(self.compression.is_finite() && self.compression >= 1.0) {
            return Err(format!(
                "compression must be >= 1, got {}",
                self.compression
            ));
        }
        if !(self.rate_hz.is_finite() && self.rate_hz >= 0.0) {
            return Err(format!(
                "rate_hz must be finite and >= 0, got {}",
                self.rate_hz
            ));
        }
        Ok(())
    }
}

fn main() -> ExitCode {
    let args = ServiceArgs::parse();
    init_logging(SERVICE);
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            error!("{e:#}");
            ExitCode::FAILURE
        }
    }
}

/// The simulator, the scenario and the frame clock.
struct Source {
    simulator: LidarSimulator,
    scenario: Box<dyn Scenario>,
    /// Frames of one pass of the scenario.
    pass_frames: u64,
    seed: u64,
}

impl Source {
    fn new(config: &Config) -> Result<Source> {
        let target = Target::resolve(&config.target, config.scale)
            .with_context(|| format!("cannot load target {:?}", config.target))?;
        let mut sc = ScenarioConfig::default_for(config.scenario);
        sc.seed = config.seed;
        sc.compression = config.compression;
        sc.range_m = config.range_m;
        sc.random_frames = sc.random_frames.max(config.frames as usize);
        sc.look_away = config.look_away;
        let scenario = spacepose_scenario::build(&sc).context("invalid scenario")?;
        let mut sensor = SensorConfig::livox_mid40();
        sensor.integration_time_s = config.integration_time_s;
        sensor.effects.clutter = config.clutter;
        let simulator = LidarSimulator::new(Arc::new(target), sensor).context("invalid sensor")?;
        let pass_frames = scenario.natural_frame_count().max(1) as u64;
        Ok(Source {
            simulator,
            scenario,
            pass_frames,
            seed: config.seed,
        })
    }

    /// Frame `k`: the scenario's frame `k mod pass`, on a sensor clock that
    /// keeps running across passes.
    fn frame(&self, k: u64) -> Result<Frame> {
        let period = self.scenario.frame_period_s();
        let pass = k / self.pass_frames;
        let t_scenario = (k % self.pass_frames + 1) as f64 * period;
        let shift = (pass * self.pass_frames) as f64 * period;
        let truth = self.scenario.state_at(t_scenario);
        let mut rng = LidarSimulator::frame_rng(self.seed, k);
        let mut frame = self
            .simulator
            .try_simulate(&truth, &mut rng)
            .with_context(|| format!("frame {k}"))?;
        if shift != 0.0 {
            frame.scan_start += shift;
            frame.scan_end += shift;
            frame.truth.t += shift;
            for p in &mut frame.points {
                p.t += shift;
            }
        }
        Ok(frame)
    }
}

/// The output ports.
struct Ports {
    raw: CloudPublisher,
    truth: Publisher<TruthMsg>,
    acquisition: Publisher<AcquisitionResult>,
    instance: Name,
}

fn run(args: &ServiceArgs) -> Result<()> {
    let config: Config = load_config(args.config.as_deref())?;
    let source = Source::new(&config)?;
    let names = Names::new(&args.prefix).context("deployment prefix")?;
    let instance = args.instance_or(SERVICE);
    let bus = Bus::open(&names, &instance).context("opening the bus")?;
    let heartbeat = Duration::from_millis(args.heartbeat_ms.max(1));
    let mut health = HealthReporter::new(&bus, &names, SERVICE, &instance, heartbeat)?;
    let ports = Ports {
        raw: bus.cloud_publisher(&names.raw_cloud(), MAX_POINTS)?,
        truth: bus.publisher(&names.truth())?,
        acquisition: bus.publisher(&names.acquisition())?,
        instance: Name::new(&instance)?,
    };
    let shutdown = shutdown_flag();
    let period = (config.rate_hz > 0.0).then(|| Duration::from_secs_f64(1.0 / config.rate_hz));
    info!(
        target = config.target,
        scenario = %config.scenario,
        frames = config.frames,
        rate_hz = config.rate_hz,
        clutter = config.clutter,
        "lidar-sim running"
    );
    let mut counters = Counters::default();
    health.send(&counters, ServiceState::Running as u8)?;
    let fingerprint = checkpoint::fingerprint(&format!("{config:?}"));
    let start = starting_point(&config, fingerprint, period, &mut counters);
    let wait_ns = start.slot_ns.saturating_sub(realtime_ns()).max(0);
    let mut next = Instant::now() + Duration::from_nanos(wait_ns as u64);
    let mut k = start.frame;
    let running = |bus: &Bus, d: Duration| -> Result<bool> {
        Ok(!shutdown.load(Ordering::Relaxed) && bus.sleep(d)?)
    };
    while config.frames == 0 || k < config.frames {
        if let Some(period) = period {
            // Sleep to the frame slot, heartbeating on the way.
            loop {
                tick(&mut health, &counters);
                let now = Instant::now();
                if now >= next {
                    break;
                }
                if !running(&bus, (next - now).min(heartbeat))? {
                    return stop(&mut health, &counters);
                }
            }
            next = next.max(Instant::now().checked_sub(period).unwrap_or(next)) + period;
        } else if shutdown.load(Ordering::Relaxed) {
            return stop(&mut health, &counters);
        }
        // Before publishing: a crash in between loses frame k, never
        // publishes it twice.
        save_checkpoint(&config, k, fingerprint, &mut counters);
        match source.frame(k) {
            Ok(frame) => publish(&ports, &config, &frame, k, &mut counters),
            Err(e) => {
                warn!("{e:#}");
                counters.errors += 1;
            }
        }
        tick(&mut health, &counters);
        k += 1;
    }
    if !config.exit_at_end {
        info!("all {k} frames published; idle");
        while running(&bus, heartbeat)? {
            tick(&mut health, &counters);
        }
    }
    stop(&mut health, &counters)
}

/// Where this instance starts: frame 0 now, or, after a restart, the frame
/// due now on its predecessor's frame grid (from the checkpoint). A
/// checkpoint that cannot be used is reported and frame 0 taken.
fn starting_point(
    config: &Config,
    fingerprint: u64,
    period: Option<Duration>,
    counters: &mut Counters,
) -> Resume {
    let now = realtime_ns();
    let fresh = Resume {
        frame: 0,
        slot_ns: now,
    };
    let Some(path) = &config.checkpoint_file else {
        return fresh;
    };
    let period_ns = period.map(|p| i64::try_from(p.as_nanos()).unwrap_or(i64::MAX));
    let max_age_ns = (config.checkpoint_max_age_s * 1e9) as i64;
    match Checkpoint::load(path) {
        Ok(None) => fresh,
        Ok(Some(c)) if c.fingerprint != fingerprint => {
            warn!(path = %path.display(), "checkpoint of another configuration ignored: starting at frame 0");
            fresh
        }
        Ok(Some(c)) if now.saturating_sub(c.slot_ns) > max_age_ns => {
            warn!(path = %path.display(), frame = c.frame, "checkpoint older than checkpoint_max_age_s ignored: starting at frame 0");
            fresh
        }
        Ok(Some(c)) => {
            let r = c.resume(now, period_ns);
            info!(
                last_frame = c.frame,
                resume_frame = r.frame,
                missed = r.frame - c.frame - 1,
                due_in_ms = r.slot_ns.saturating_sub(now) as f64 * 1e-6,
                "restarted: resuming the scenario at the frame now due"
            );
            r
        }
        Err(e) => {
            warn!("{e:#}: starting at frame 0");
            counters.errors += 1;
            fresh
        }
    }
}

/// Records that frame `k` takes its slot now.
fn save_checkpoint(config: &Config, k: u64, fingerprint: u64, counters: &mut Counters) {
    let Some(path) = &config.checkpoint_file else {
        return;
    };
    let c = Checkpoint {
        frame: k,
        slot_ns: realtime_ns(),
        fingerprint,
    };
    if let Err(e) = c.save(path) {
        warn!(sequence = k, "{e:#}");
        counters.errors += 1;
    }
}

/// Acquisition (first frame, `truth_init`), then the truth, then the cloud:
/// once the cloud is out, the scorers have the frame's truth, even if the
/// sensor dies right after (a kill between the two would otherwise leave a
/// tracked frame without truth).
fn publish(ports: &Ports, config: &Config, frame: &Frame, k: u64, c: &mut Counters) {
    c.frames_in += 1;
    if k == 0 && config.truth_init {
        let mut acq = AcquisitionResult::new();
        acq.method = AcquisitionMethod::Truth as u8;
        acq.success = 1;
        acq.sequence = 0;
        acq.t_s = frame.truth.t;
        (acq.q_sensor_target, acq.p_sensor_target) = pose_to_wire(&frame.truth.t_sensor_target);
        acq.instance = ports.instance;
        if let Err(e) = ports.acquisition.send(&acq) {
            warn!("publishing the truth acquisition: {e}");
            c.errors += 1;
        }
    }
    if let Err(e) = ports.truth.send(&truth_msg(k, &frame.truth)) {
        warn!(sequence = k, "publishing the truth: {e}");
        c.errors += 1;
    }
    let mut header = CloudHeader::new(k, frame.scan_start, frame.scan_end);
    header.sensor_id = config.sensor_id;
    match ports.raw.send(header, &frame.points) {
        Ok(()) => {
            c.frames_out += 1;
            c.last_frame = k;
        }
        Err(e) => {
            warn!(sequence = k, "publishing the frame: {e}");
            if frame.points.len() > ports.raw.capacity() {
                c.rejected_oversized += 1;
            } else {
                c.errors += 1;
            }
        }
    }
}

fn truth_msg(sequence: u64, truth: &TruthState) -> TruthMsg {
    let mut msg = TruthMsg::new();
    msg.sequence = sequence;
    msg.t_s = truth.t;
    (msg.q_sensor_target, msg.p_sensor_target) = pose_to_wire(&truth.t_sensor_target);
    msg.v_sensor = vector3_to_wire(&truth.v_sensor_target);
    msg.w_target = vector3_to_wire(&truth.w_target);
    msg
}

fn tick(health: &mut HealthReporter, c: &Counters) {
    if let Err(e) = health.tick(c, ServiceState::Running as u8) {
        warn!("{e:#}");
    }
}

fn stop(health: &mut HealthReporter, c: &Counters) -> Result<()> {
    info!("lidar-sim stopping");
    health.send(c, ServiceState::Stopping as u8)
}
