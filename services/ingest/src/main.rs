//! `spacepose-ingest`: subscribes to raw clouds, the filter state and
//! acquisition results; publishes each raw frame cropped to the target's
//! region of interest and voxel-filtered (same header, new point count),
//! plus a health heartbeat. Bad frames are logged and counted, never fatal.
//! A well-formed frame without the target (empty, or too few points after
//! the crop) is forwarded as it is: "target not seen" is an observation the
//! tracker must see to report the loss (crate docs of `spacepose_ingest`).

use anyhow::{Context, Result};
use clap::Parser;
use serde::Deserialize;
use spacepose_bus::{Bus, CloudPublisher, CloudSubscriber, Subscriber, WakeReason};
use spacepose_ingest::{
    AttitudePrediction, FrameReport, IngestConfig, IngestStage, TargetPrediction,
};
use spacepose_messages::convert::{rotation_from_wxyz, vector3_from_wire};
use spacepose_messages::{AcquisitionResult, FilterState, Names, ServiceState};
use spacepose_service_kit::{
    Counters, HealthReporter, ServiceArgs, ServiceConfig, init_logging, load_config, shutdown_flag,
};
use std::process::ExitCode;
use std::sync::atomic::Ordering;
use std::time::Duration;
use tracing::{error, info, warn};

const SERVICE: &str = "ingest";

/// The service configuration: the library's [`IngestConfig`] as is.
#[derive(Debug, Default, Deserialize)]
#[serde(transparent)]
struct Config(IngestConfig);

impl ServiceConfig for Config {
    fn validate(&self) -> Result<(), String> {
        self.0.validate().map_err(|e| e.to_string())
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
    let Config(config) = load_config(args.config.as_deref())?;
    let names = Names::new(&args.prefix).context("deployment prefix")?;
    let instance = args.instance_or(SERVICE);
    let bus = Bus::open(&names, &instance).context("opening the bus")?;
    let shutdown = shutdown_flag();
    let heartbeat = Duration::from_millis(args.heartbeat_ms.max(1));
    let mut health = HealthReporter::new(&bus, &names, SERVICE, &instance, heartbeat)?;
    let mut node = Node::open(&bus, &names, config)?;
    let mut waiter = bus.waitset()?;
    waiter.attach(&node.filter_state)?;
    waiter.attach(&node.acquisition)?;
    waiter.attach(&node.raw)?;
    info!(prefix = names.prefix(), instance, "ingest running");
    health.send(&node.counters(), ServiceState::Running as u8)?;
    loop {
        let reason = waiter.wait(heartbeat)?;
        if reason == WakeReason::TerminationRequested || shutdown.load(Ordering::Relaxed) {
            break;
        }
        node.poll();
        if let Err(e) = health.tick(&node.counters(), ServiceState::Running as u8) {
            warn!("{e:#}");
            node.errors += 1;
        }
    }
    info!("ingest stopping");
    health.send(&node.counters(), ServiceState::Stopping as u8)
}

/// Ports, the ingest stage and the latest prediction.
struct Node {
    raw: CloudSubscriber,
    filter_state: Subscriber<FilterState>,
    acquisition: Subscriber<AcquisitionResult>,
    out: CloudPublisher,
    stage: IngestStage,
    prediction: Option<TargetPrediction>,
    buffer: Vec<spacepose_geometry::Point>,
    frames_out: u64,
    last_frame: u64,
    errors: u64,
    /// Whether the last forwarded frame showed the target (for the log).
    target_seen: bool,
}

impl Node {
    fn open(bus: &Bus, names: &Names, config: IngestConfig) -> Result<Node> {
        // The output is never larger than the largest accepted input.
        let out = bus.cloud_publisher(&names.cloud(), config.max_points)?;
        Ok(Node {
            raw: bus.cloud_subscriber(&names.raw_cloud())?,
            filter_state: bus.subscriber(&names.filter_state())?,
            acquisition: bus.subscriber(&names.acquisition())?,
            out,
            stage: IngestStage::new(config)?,
            prediction: None,
            buffer: Vec::new(),
            frames_out: 0,
            last_frame: 0,
            errors: 0,
            target_seen: true,
        })
    }

    /// Health counters: the stage's rejections plus bus errors. Empty
    /// frames are forwarded (in `frames_out`), so `rejected_empty` stays 0;
    /// the health message has no field for `frames_without_target` yet (it
    /// is in the stage's stats and the log).
    fn counters(&self) -> Counters {
        let s = self.stage.stats();
        Counters {
            frames_in: s.frames_in,
            frames_out: self.frames_out,
            rejected_non_finite: s.frames_with_non_finite,
            rejected_empty: 0,
            rejected_oversized: s.rejected_oversized,
            rejected_wire: 0,
            errors: s.rejected_other + self.errors,
            last_frame: self.last_frame,
        }
    }

    /// Drains predictions first, then the raw frames.
    fn poll(&mut self) {
        while let Some(state) = self.recv(|n| n.filter_state.try_recv()) {
            if state.initialized == 1 {
                self.update_prediction(from_filter_state(&state));
            }
        }
        while let Some(acq) = self.recv(|n| n.acquisition.try_recv()) {
            if acq.success == 1 {
                self.update_prediction(from_acquisition(&acq));
            }
        }
        while let Some(sample) = self.recv(|n| n.raw.try_recv()) {
            let header = *sample.header();
            let result = self.stage.process_into(
                sample.points(),
                header.scan_start_s,
                header.scan_end_s,
                self.prediction.as_ref(),
                &mut self.buffer,
            );
            drop(sample);
            match result {
                Ok(report) => {
                    if report.non_finite_points > 0 {
                        warn!(
                            sequence = header.sequence,
                            "dropped {} non-finite points", report.non_finite_points
                        );
                    }
                    self.log_target_seen(header.sequence, &report);
                    match self.out.send(header, &self.buffer) {
                        Ok(()) => {
                            self.frames_out += 1;
                            self.last_frame = header.sequence;
                        }
                        Err(e) => {
                            warn!(sequence = header.sequence, "publishing: {e}");
                            self.errors += 1;
                        }
                    }
                }
                Err(e) => warn!(sequence = header.sequence, "frame rejected: {e}"),
            }
        }
    }

    /// Logs when the target disappears from the frames and when it is back.
    fn log_target_seen(&mut self, sequence: u64, report: &FrameReport) {
        if report.target_seen == self.target_seen {
            return;
        }
        self.target_seen = report.target_seen;
        let without = self.stage.stats().frames_without_target;
        if report.target_seen {
            info!(
                sequence,
                points = report.output_points,
                frames_without_target = without,
                "target seen again"
            );
        } else {
            info!(
                sequence,
                input_points = report.input_points,
                points = report.output_points,
                "target not seen: forwarding the frame as an observation"
            );
        }
    }

    /// One receive; a bus error is logged, counted and ends the drain.
    fn recv<T, E: std::fmt::Display>(
        &mut self,
        f: impl FnOnce(&Self) -> Result<Option<T>, E>,
    ) -> Option<T> {
        match f(self) {
            Ok(v) => v,
            Err(e) => {
                warn!("receive: {e}");
                self.errors += 1;
                None
            }
        }
    }

    /// Keeps the most recent valid prediction.
    fn update_prediction(&mut self, candidate: Result<TargetPrediction, String>) {
        match candidate {
            Ok(p) if p.is_finite() => {
                if self.prediction.is_none_or(|old| p.t_s >= old.t_s) {
                    self.prediction = Some(p);
                }
            }
            Ok(_) => {
                warn!("non-finite prediction ignored");
                self.errors += 1;
            }
            Err(e) => {
                warn!("prediction ignored: {e}");
                self.errors += 1;
            }
        }
    }
}

/// Position, velocity, attitude and angular velocity of the filter.
fn from_filter_state(s: &FilterState) -> Result<TargetPrediction, String> {
    let r = rotation_from_wxyz(&s.q_sensor_target).map_err(|e| e.to_string())?;
    Ok(TargetPrediction {
        t_s: s.t_s,
        p_sensor_target: vector3_from_wire(&s.p_sensor_target),
        v_sensor: vector3_from_wire(&s.v_sensor),
        attitude: Some(AttitudePrediction {
            r_sensor_target: r,
            w_target: vector3_from_wire(&s.w_target),
            sigma_rot_rad: worst_sigma(&s.attitude_covariance, 0),
            sigma_w_radps: worst_sigma(&s.attitude_covariance, 3),
        }),
    })
}

/// Square root of the largest diagonal entry of the 3×3 block starting at
/// `first` of a 6×6 covariance (the worst-axis standard deviation).
fn worst_sigma(covariance: &[[f64; 6]; 6], first: usize) -> f64 {
    (first..first + 3)
        .map(|i| covariance[i][i])
        .fold(0.0_f64, f64::max)
        .sqrt()
}

/// An acquired pose gives the position only: its velocities are unknown, so
/// the attitude (which would need ω over the scan) is not used.
fn from_acquisition(a: &AcquisitionResult) -> Result<TargetPrediction, String> {
    Ok(TargetPrediction {
        t_s: a.t_s,
        p_sensor_target: vector3_from_wire(&a.p_sensor_target),
        v_sensor: nalgebra::Vector3::zeros(),
        attitude: None,
    })
}
