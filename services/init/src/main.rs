//! `spacepose-init`: acquires the pose at start and whenever the tracker
//! reports `lost`, and publishes an `AcquisitionResult` per attempt (the
//! tracker and the filter restart from an accepted one; a rejected one is
//! retried on a later frame). Wakes on cropped clouds and tracker
//! estimates. Logic: [`InitStateMachine`] and [`MethodChain`].

use anyhow::Context;
use clap::Parser;
use serde::Deserialize;
use spacepose_bus::{Bus, CloudSubscriber, Publisher, Subscriber, WakeReason};
use spacepose_geometry::Point;
use spacepose_init::Acquisition;
use spacepose_init::{EstimateInfo, Event, InitServiceConfig, InitStateMachine, MethodChain};
use spacepose_messages::clock::realtime_ns;
use spacepose_messages::{AcquisitionResult, Name, Names, PoseEstimate, ServiceState};
use spacepose_service_kit::{
    Counters, HealthReporter, ServiceArgs, ServiceConfig, init_logging, load_config, shutdown_flag,
};
use std::process::ExitCode;
use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, Sender, channel};
use std::time::{Duration, Instant};

const SERVICE: &str = "init";

/// The service configuration as a TOML file ([`InitServiceConfig`]).
#[derive(Debug, Default, Deserialize)]
#[serde(transparent)]
struct Config(InitServiceConfig);

impl ServiceConfig for Config {
    fn validate(&self) -> Result<(), String> {
        self.0.validate().map_err(|e| e.to_string())
    }
}

fn main() -> ExitCode {
    match run(ServiceArgs::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!("{e:#}");
            eprintln!("spacepose-init: {e:#}");
            ExitCode::FAILURE
        }
    }
}

struct Ports {
    clouds: CloudSubscriber,
    estimates: Subscriber<PoseEstimate>,
    results: Publisher<AcquisitionResult>,
}

/// The newest frame, kept until it is used or replaced.
struct Held {
    sequence: u64,
    scan_end_s: f64,
    points: Vec<Point>,
}

/// A finished acquisition from the worker thread.
struct Done {
    sequence: u64,
    scan_end_s: f64,
    points_in: usize,
    acquisition: Acquisition,
}

/// The methods run on their own thread: an acquisition takes longer than a
/// heartbeat period, and the main loop keeps heartbeating (the supervisor
/// kills a service that goes silent) and reading the tracker meanwhile.
fn spawn_worker(chain: MethodChain) -> anyhow::Result<(Sender<Held>, Receiver<Done>)> {
    let (job_tx, job_rx) = channel::<Held>();
    let (done_tx, done_rx) = channel::<Done>();
    std::thread::Builder::new()
        .name("acquisition".into())
        .spawn(move || {
            for job in job_rx {
                let acquisition = chain.acquire(&job.points);
                let done = Done {
                    sequence: job.sequence,
                    scan_end_s: job.scan_end_s,
                    points_in: job.points.len(),
                    acquisition,
                };
                if done_tx.send(done).is_err() {
                    return;
                }
            }
        })
        .context("starting the acquisition thread")?;
    Ok((job_tx, done_rx))
}

/// The service's moving parts.
struct Node {
    ports: Ports,
    machine: InitStateMachine,
    jobs: Sender<Held>,
    done: Receiver<Done>,
    busy: bool,
    instance: Name,
    held: Option<Held>,
    counters: Counters,
}

fn run(args: ServiceArgs) -> anyhow::Result<()> {
    init_logging(SERVICE);
    let Config(config) = load_config(args.config.as_deref())?;
    let names = Names::new(&args.prefix).context("deployment prefix")?;
    let instance = args
        .instance
        .clone()
        .or_else(|| config.instance.clone())
        .unwrap_or_else(|| SERVICE.to_string());
    let instance_name = Name::new(&instance).context("instance name")?;
    let shutdown = shutdown_flag();

    let started = Instant::now();
    let chain = config.build_chain()?;
    let methods: Vec<&str> = chain.methods().iter().map(|m| m.as_str()).collect();
    tracing::info!(
        target = config.target,
        ?methods,
        ms = started.elapsed().as_millis() as u64,
        "acquisition methods ready"
    );

    let bus = Bus::open(&names, &instance).context("opening the bus")?;
    let ports = Ports {
        clouds: bus.cloud_subscriber(&names.cloud())?,
        estimates: bus.subscriber(&names.pose())?,
        results: bus.publisher(&names.acquisition())?,
    };
    let heartbeat = Duration::from_millis(args.heartbeat_ms.max(1));
    let mut health = HealthReporter::new(&bus, &names, SERVICE, &instance, heartbeat)?;
    let mut waiter = bus.waitset()?;
    waiter.attach(&ports.clouds)?;
    waiter.attach(&ports.estimates)?;
    let (jobs, done) = spawn_worker(chain)?;
    let mut node = Node {
        ports,
        machine: InitStateMachine::new(config.state.clone())?,
        jobs,
        done,
        busy: false,
        instance: instance_name,
        held: None,
        counters: Counters::default(),
    };
    tracing::info!(prefix = names.prefix(), instance, "init service running");
    // While an acquisition runs, wake often enough to publish it promptly.
    let busy_poll = Duration::from_millis(10).min(heartbeat);
    while !shutdown.load(Ordering::Relaxed) {
        let timeout = if node.busy { busy_poll } else { heartbeat };
        if waiter.wait(timeout)? == WakeReason::TerminationRequested {
            break;
        }
        node.drain_estimates();
        node.drain_clouds();
        node.publish_finished()?;
        node.start_if_wanted()?;
        health.tick(&node.counters, ServiceState::Running as u8)?;
    }
    tracing::info!(stats = ?node.machine.stats(), "init service stopping");
    health.send(&node.counters, ServiceState::Stopping as u8)?;
    Ok(())
}

impl Node {
    /// Tracker estimates into the state machine.
    fn drain_estimates(&mut self) {
        loop {
            match self.ports.estimates.try_recv() {
                Ok(Some(e)) => match EstimateInfo::from_wire(&e) {
                    Ok(info) => log_event(self.machine.on_estimate(&info)),
                    Err(err) => {
                        self.counters.rejected_wire += 1;
                        tracing::warn!("estimate refused: {err}");
                    }
                },
                Ok(None) => return,
                Err(err) => {
                    self.counters.errors += 1;
                    tracing::warn!("receiving an estimate: {err}");
                    return;
                }
            }
        }
    }

    /// Keeps a copy of the newest cloud (a loss reported later may use it:
    /// it is not older than the loss).
    fn drain_clouds(&mut self) {
        loop {
            let sample = match self.ports.clouds.try_recv() {
                Ok(Some(s)) => s,
                Ok(None) => return,
                Err(err) => {
                    self.counters.errors += 1;
                    tracing::warn!("receiving a cloud: {err}");
                    return;
                }
            };
            let header = *sample.header();
            self.counters.frames_in += 1;
            self.counters.last_frame = header.sequence;
            self.machine.on_frame(header.sequence);
            self.held = Some(Held {
                sequence: header.sequence,
                scan_end_s: header.scan_end_s,
                points: sample.points().to_vec(),
            });
        }
    }

    /// Hands the held frame to the worker when the state machine wants it
    /// and no acquisition is running.
    fn start_if_wanted(&mut self) -> anyhow::Result<()> {
        if self.busy {
            return Ok(());
        }
        // The tracker may have recovered meanwhile.
        self.drain_estimates();
        if !self
            .held
            .as_ref()
            .is_some_and(|h| self.machine.wants(h.sequence))
        {
            return Ok(());
        }
        if let Some(job) = self.held.take() {
            self.jobs
                .send(job)
                .map_err(|_| anyhow::anyhow!("the acquisition thread ended"))?;
            self.busy = true;
        }
        Ok(())
    }

    /// Publishes a finished acquisition and tells the state machine.
    fn publish_finished(&mut self) -> anyhow::Result<()> {
        let done = match self.done.try_recv() {
            Ok(d) => d,
            Err(std::sync::mpsc::TryRecvError::Empty) => return Ok(()),
            Err(std::sync::mpsc::TryRecvError::Disconnected) => {
                anyhow::bail!("the acquisition thread ended")
            }
        };
        self.busy = false;
        let acquisition = &done.acquisition;
        // An empty frame is an observation (the target is not in view:
        // ingest forwards it on purpose), not bad input: not counted.
        if done.points_in > 0 && acquisition.points < done.points_in {
            self.counters.rejected_non_finite += 1;
        }
        let msg = acquisition.to_wire(done.sequence, done.scan_end_s, self.instance);
        let published_ns = match self.ports.results.send(&msg) {
            Ok(()) => {
                self.counters.frames_out += 1;
                Some(realtime_ns())
            }
            Err(err) => {
                self.counters.errors += 1;
                tracing::warn!("publishing the acquisition result: {err}");
                None
            }
        };
        let accepted = msg.success == 1 && published_ns.is_some();
        tracing::info!(
            sequence = done.sequence,
            success = msg.success,
            method = msg.method,
            f_conv_m2 = msg.f_conv_m2,
            time_ms = acquisition.time_ms,
            "acquisition: {}",
            acquisition.summary()
        );
        log_event(
            self.machine
                .on_acquisition(done.sequence, accepted, published_ns),
        );
        Ok(())
    }
}

fn log_event(event: Event) {
    match event {
        Event::None => {}
        Event::LossDetected { frame } => tracing::info!(frame, "track lost: acquiring"),
        Event::HandoverFailed { frame } => {
            tracing::warn!(
                frame,
                "the tracker lost the handed-over pose: acquiring again"
            )
        }
        Event::TrackerTracking { frame } => tracing::info!(frame, "the tracker tracks"),
        Event::Accepted {
            frame,
            delay_frames,
        } => tracing::info!(frame, ?delay_frames, "pose acquired and handed over"),
        Event::Rejected { frame, retry_from } => {
            tracing::info!(
                frame,
                retry_from,
                "acquisition rejected: retrying on a later frame"
            )
        }
    }
}
