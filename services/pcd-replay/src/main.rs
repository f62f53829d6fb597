//! `spacepose-pcd-replay`: publishes a directory of recorded frames as raw
//! clouds, at a configured rate or at the recorded scan period, optionally
//! in a loop (each pass continues the sensor clock). Corrupt files are
//! logged, counted and skipped.

use anyhow::{Context, Result};
use clap::Parser;
use serde::Deserialize;
use spacepose_bus::{Bus, CloudPublisher};
use spacepose_messages::{CloudHeader, MAX_POINTS, Names, ServiceState};
use spacepose_pcd_replay::{ReplayDir, ReplayFrame};
use spacepose_service_kit::{
    Counters, HealthReporter, ServiceArgs, ServiceConfig, init_logging, load_config, shutdown_flag,
};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use tracing::{error, info, warn};

const SERVICE: &str = "pcd-replay";

/// Replay settings.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct Config {
    /// Directory of `frame_NNNNNN.pcd` / `.ply` (and `truth.csv`).
    dir: PathBuf,
    /// Frames per second; 0 = the recorded period (truth.csv), else 1 Hz.
    rate_hz: f64,
    /// Start again after the last frame.
    #[serde(rename = "loop")]
    looping: bool,
    /// Exit after the last frame (no loop); otherwise keep sending heartbeats.
    exit_at_end: bool,
    /// Sensor id written in the cloud headers.
    sensor_id: u16,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            dir: PathBuf::from("frames"),
            rate_hz: 0.0,
            looping: false,
            exit_at_end: false,
            sensor_id: 0,
        }
    }
}

impl ServiceConfig for Config {
    fn validate(&self) -> Result<(), String> {
        if !(self.rate_hz.is_finite() && self.rate_hz >= 0.0) {
            return Err(format!(
                "rate_hz must be finite and >= 0, got {}",
                self.rate_hz
            ));
        }
        if self.dir.as_os_str().is_empty() {
            return Err("dir must not be empty".into());
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

fn run(args: &ServiceArgs) -> Result<()> {
    let config: Config = load_config(args.config.as_deref())?;
    let dir = ReplayDir::open(&config.dir)?;
    for w in dir.warnings() {
        warn!("{w}");
    }
    let period = if config.rate_hz > 0.0 {
        Duration::from_secs_f64(1.0 / config.rate_hz)
    } else {
        Duration::from_secs_f64(dir.recorded_period_s().unwrap_or(1.0))
    };
    let names = Names::new(&args.prefix).context("deployment prefix")?;
    let instance = args.instance_or(SERVICE);
    let bus = Bus::open(&names, &instance).context("opening the bus")?;
    let heartbeat = Duration::from_millis(args.heartbeat_ms.max(1));
    let mut health = HealthReporter::new(&bus, &names, SERVICE, &instance, heartbeat)?;
    let publisher = bus.cloud_publisher(&names.raw_cloud(), MAX_POINTS)?;
    info!(
        frames = dir.len(),
        period_s = period.as_secs_f64(),
        dir = %config.dir.display(),
        "replay running"
    );
    let mut replay = Replay {
        publisher,
        counters: Counters::default(),
        sequence: 0,
        sensor_id: config.sensor_id,
    };
    let shutdown = shutdown_flag();
    let mut clock = Pacer::new(period, heartbeat, shutdown);
    health.send(&replay.counters, ServiceState::Running as u8)?;
    let mut time_shift = 0.0;
    'passes: loop {
        let (mut first_start, mut last_end) = (None::<f64>, None::<f64>);
        for result in dir.iter() {
            let mut frame = match result {
                Ok(f) => f,
                Err(e) => {
                    warn!("skipped: {e}");
                    replay.counters.errors += 1;
                    continue;
                }
            };
            first_start.get_or_insert(frame.scan_start_s);
            last_end = Some(frame.scan_end_s);
            frame.shift_time(time_shift);
            if !clock.wait_slot(&bus, &mut health, &replay.counters)? {
                break 'passes;
            }
            replay.publish(&frame);
        }
        if !config.looping {
            break;
        }
        // The next pass continues the clock one period after this one.
        if let (Some(a), Some(b)) = (first_start, last_end) {
            time_shift += (b - a) + period.as_secs_f64();
        }
    }
    if !config.exit_at_end {
        info!("end of the recording; idle");
        while clock.idle(&bus, &mut health, &replay.counters)? {}
    }
    health.send(&replay.counters, ServiceState::Stopping as u8)
}

/// The publisher and its counters.
struct Replay {
    publisher: CloudPublisher,
    counters: Counters,
    sequence: u64,
    sensor_id: u16,
}

impl Replay {
    fn publish(&mut self, frame: &ReplayFrame) {
        self.counters.frames_in += 1;
        let mut header = CloudHeader::new(self.sequence, frame.scan_start_s, frame.scan_end_s);
        header.sensor_id = self.sensor_id;
        self.sequence += 1;
        if frame.points.len() > self.publisher.capacity() {
            warn!(path = %frame.path.display(), "{} points exceed the capacity", frame.points.len());
            self.counters.rejected_oversized += 1;
            return;
        }
        match self.publisher.send(header, &frame.points) {
            Ok(()) => {
                self.counters.frames_out += 1;
                self.counters.last_frame = header.sequence;
            }
            Err(e) => {
                warn!("publishing {}: {e}", frame.path.display());
                self.counters.errors += 1;
            }
        }
    }
}

/// Frame slots at a fixed period, heartbeats in between, stop on signals.
struct Pacer {
    period: Duration,
    heartbeat: Duration,
    next: Instant,
    shutdown: Arc<AtomicBool>,
}

impl Pacer {
    fn new(period: Duration, heartbeat: Duration, shutdown: Arc<AtomicBool>) -> Pacer {
        Pacer {
            period,
            heartbeat,
            next: Instant::now(),
            shutdown,
        }
    }

    /// Waits for the next frame slot; false when the service must stop.
    fn wait_slot(&mut self, bus: &Bus, health: &mut HealthReporter, c: &Counters) -> Result<bool> {
        loop {
            tick(health, c);
            let now = Instant::now();
            if self.shutdown.load(Ordering::Relaxed) {
                return Ok(false);
            }
            if now >= self.next {
                // Late slots are not caught up: the next one is a period later.
                let floor = now.checked_sub(self.period).unwrap_or(now);
                self.next = self.next.max(floor) + self.period;
                return Ok(true);
            }
            if !bus.sleep((self.next - now).min(self.heartbeat))? {
                return Ok(false);
            }
        }
    }

    /// One heartbeat period of idling; false when the service must stop.
    fn idle(&mut self, bus: &Bus, health: &mut HealthReporter, c: &Counters) -> Result<bool> {
        tick(health, c);
        Ok(!self.shutdown.load(Ordering::Relaxed) && bus.sleep(self.heartbeat)?)
    }
}

fn tick(health: &mut HealthReporter, c: &Counters) {
    if let Err(e) = health.tick(c, ServiceState::Running as u8) {
        warn!("{e:#}");
    }
}
