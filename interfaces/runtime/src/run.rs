//! The one `main` of every service: arguments, logging, configuration
//! (with `--check`), the zenoh link, the bus, health, the wait, the drain,
//! deadlines and shutdown, around a [`Node`].

use crate::args::ServiceArgs;
use crate::config::{ServiceConfig, load_config};
use crate::health::HealthReporter;
use crate::link::Link;
use crate::node::{Ctx, Flow, Node, NodeInfo};
use crate::ports::{BusOutbox, Ports};
use crate::runtime::{init_logging, shutdown_flag};
use anyhow::Context;
use clap::Parser;
use spacepose_bus::{Bus, WakeReason};
use spacepose_messages::{Counters, Name, Names, ServiceState, realtime_ns};
use std::process::ExitCode;
use std::sync::atomic::Ordering;
use std::time::Duration;

/// Runs the service `N` as a process: the whole body of its `main`.
pub fn main<N: Node>() -> ExitCode {
    let args = ServiceArgs::parse();
    init_logging(N::KIND.as_str());
    match run::<N>(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!("{e:#}");
            eprintln!("{}: {e:#}", N::KIND.binary_name());
            ExitCode::FAILURE
        }
    }
}

/// The instance name: `--instance`, else the configuration's, else the kind.
fn instance_of<C: ServiceConfig>(args: &ServiceArgs, config: &C, kind: &str) -> String {
    args.instance
        .clone()
        .or_else(|| config.instance().map(str::to_string))
        .unwrap_or_else(|| kind.to_string())
}

fn run<N: Node>(args: &ServiceArgs) -> anyhow::Result<()> {
    let kind = N::KIND.as_str();
    let config: N::Config = load_config(args.config.as_deref())?;
    let names = Names::new(&args.prefix).context("deployment prefix")?;
    let instance = instance_of(args, &config, kind);
    let heartbeat = Duration::from_millis(args.heartbeat_ms.max(1));
    let info = NodeInfo {
        instance: Name::new(&instance).context("instance name")?,
        names: names.clone(),
        heartbeat,
    };
    let shutdown = shutdown_flag();
    let spec = N::link(&config, &names)?;
    let mut link = spec.as_ref().map(|s| Link::open(s, &names)).transpose()?;
    let mut node = N::new(config, &info)?;
    if let (Some(link), Some(json)) = (link.as_ref(), node.latest_json()) {
        link.set_latest(json);
    }
    let bus = Bus::open(&names, &instance).context("opening the bus")?;
    let mut waiter = bus.waitset()?;
    let ports = Ports::open(&bus, &names, N::KIND, &mut waiter)?;
    if let (Some(link), Some(spec)) = (link.as_mut(), spec.as_ref()) {
        link.start(spec, &|| shutdown.load(Ordering::Relaxed))?;
    }
    let mut health = HealthReporter::new(&bus, &names, kind, &instance, heartbeat)?;
    let mut counters = Counters::default();
    tracing::info!(prefix = names.prefix(), instance, "{kind} running");
    loop {
        let mut outbox = BusOutbox {
            ports: &ports,
            link: link.as_mut(),
        };
        let flow = step(&mut node, &ports, &mut outbox, &mut counters);
        if let (Some(link), Some(json)) = (outbox.link, node.latest_json()) {
            link.set_latest(json);
        }
        if let Err(e) = health.tick(&counters, node.state() as u8) {
            counters.errors += 1;
            tracing::warn!("{e:#}");
        }
        if flow == Flow::Finished || shutdown.load(Ordering::Relaxed) {
            break;
        }
        if waiter.wait(timeout(&node, heartbeat))? == WakeReason::TerminationRequested {
            break;
        }
    }
    tracing::info!("{kind} stopping");
    let mut outbox = BusOutbox {
        ports: &ports,
        link: link.as_mut(),
    };
    if let Some(l) = outbox.link.as_deref_mut() {
        l.refresh();
    }
    let status = outbox.link.as_ref().map(|l| l.status.clone());
    let mut ctx = Ctx::new(&mut outbox, &mut counters, realtime_ns());
    ctx.link = status.as_ref();
    node.stop(&mut ctx);
    health.send(&counters, ServiceState::Stopping as u8)?;
    match link {
        Some(l) => l.stop(),
        None => Ok(()),
    }
}

/// One wake-up: the inputs, then the poll.
fn step<N: Node>(
    node: &mut N,
    ports: &Ports,
    outbox: &mut BusOutbox<'_>,
    counters: &mut Counters,
) -> Flow {
    if let Some(l) = outbox.link.as_deref_mut() {
        l.refresh();
    }
    let status = outbox.link.as_ref().map(|l| l.status.clone());
    let mut ctx = Ctx::new(outbox, counters, realtime_ns());
    ctx.link = status.as_ref();
    ports.drain(node, &mut ctx);
    node.poll(&mut ctx)
}

/// Until the node's next deadline (just after it), at most a heartbeat.
fn timeout<N: Node>(node: &N, heartbeat: Duration) -> Duration {
    match node.next_wake_ns() {
        Some(at) => {
            let left_ns = at.saturating_sub(realtime_ns()).max(0) as u64;
            heartbeat.min(Duration::from_nanos(left_ns) + Duration::from_micros(200))
        }
        None => heartbeat,
    }
}
