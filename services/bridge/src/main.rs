//! `spacepose-bridge`: the host bridge of a partitioned suite (see the
//! library docs). Opens the host's link session (listening hosts check the
//! peers' accounts and enforce the link ACL; connecting hosts present
//! theirs), starts the bus's `Bridge` with the configured routes on the
//! link keys, optionally waits for the consuming hosts, then reports its
//! counters in its heartbeat and in `stats_file`.

use anyhow::Context;
use clap::Parser;
use serde::Deserialize;
use spacepose_bridge::{BridgeServiceConfig, RouteDirection, link_key};
use spacepose_bus::zenoh::Wait;
use spacepose_bus::{
    AccessControl, Bridge, Bus, Credentials, Direction, Route, ZenohConfig, open_zenoh_with, zenoh,
};
use spacepose_messages::{Names, ServiceState};
use spacepose_service_kit::{
    Counters, HealthReporter, ServiceArgs, ServiceConfig, init_logging, load_config, shutdown_flag,
};
use std::process::ExitCode;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

const SERVICE: &str = "bridge";

/// The service configuration as a TOML file ([`BridgeServiceConfig`]).
#[derive(Debug, Default, Deserialize)]
#[serde(transparent)]
struct Config(BridgeServiceConfig);

impl ServiceConfig for Config {
    fn validate(&self) -> Result<(), String> {
        self.0.validate().map_err(|e| e.to_string())?;
        // Accounts and files are checked too (`--check`).
        if let Some(a) = &self.0.access {
            access_control(a)
                .validate_link()
                .map_err(|e| e.to_string())?;
        }
        if let Some(path) = &self.0.credentials_file {
            Credentials::from_file(path).map_err(|e| e.to_string())?;
        }
        Ok(())
    }
}

fn access_control(a: &spacepose_bridge::LinkAccess) -> AccessControl {
    AccessControl {
        dictionary_file: a.dictionary_file.clone(),
        operators: Vec::new(),
        readers: Vec::new(),
        peers: a.peers.clone(),
    }
}

fn main() -> ExitCode {
    match run(ServiceArgs::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!("{e:#}");
            eprintln!("spacepose-bridge: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Opens the link session of this host.
fn open_link(config: &BridgeServiceConfig, suite: &Names) -> anyhow::Result<zenoh::Session> {
    let z = ZenohConfig {
        mode: config.zenoh.mode.clone(),
        listen: config.zenoh.listen.clone(),
        connect: config.zenoh.connect.clone(),
        multicast_scouting: false,
    };
    let credentials = config
        .credentials_file
        .as_deref()
        .map(Credentials::from_file)
        .transpose()?;
    // The ACL only where this host accepts links (see AccessControl::apply_link).
    let access = config
        .access
        .as_ref()
        .filter(|_| !z.listen.is_empty())
        .map(access_control);
    match &access {
        Some(a) => {
            tracing::info!(peers = ?a.peers, "link access control on: usrpwd accounts, ACL by user name, default deny")
        }
        None => {
            let exposed = z.non_loopback_listen();
            if !exposed.is_empty() {
                tracing::warn!(
                    ?exposed,
                    "the link listens beyond loopback WITHOUT access control: anyone who \
                     reaches these endpoints can read and inject suite traffic (add [access])"
                );
            }
        }
    }
    open_zenoh_with(&z, |c| {
        if let Some(creds) = &credentials {
            creds.apply(c)?;
        }
        match &access {
            Some(a) => a.apply_link(suite, c),
            None => Ok(()),
        }
    })
    .context("opening the link session")
}

/// Waits until every outbound key has a subscriber on the link.
fn wait_for_link(
    session: &zenoh::Session,
    keys: &[String],
    timeout: Duration,
    shutdown: &std::sync::atomic::AtomicBool,
) -> anyhow::Result<()> {
    let publishers = keys
        .iter()
        .map(|k| session.declare_publisher(k.clone()).wait())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| anyhow::anyhow!("declaring a publisher: {e}"))?;
    let start = Instant::now();
    loop {
        let mut missing = Vec::new();
        for (p, k) in publishers.iter().zip(keys) {
            let matched = p.matching_status().wait().is_ok_and(|m| m.matching());
            if !matched {
                missing.push(k.as_str());
            }
        }
        if missing.is_empty() {
            tracing::info!(
                ms = start.elapsed().as_millis() as u64,
                "every outbound topic has a subscriber on the link"
            );
            return Ok(());
        }
        if start.elapsed() >= timeout || shutdown.load(Ordering::Relaxed) {
            anyhow::bail!(
                "no subscriber on the link within {} s for {} (are the consuming hosts up, \
                 reachable, and do they accept this host's account?)",
                timeout.as_secs_f64(),
                missing.join(", ")
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn run(args: ServiceArgs) -> anyhow::Result<()> {
    init_logging(SERVICE);
    let Config(config) = load_config(args.config.as_deref())?;
    let names = Names::new(&args.prefix).context("deployment prefix")?;
    let suite = config.suite()?;
    let instance = args.instance_or(SERVICE);
    let shutdown = shutdown_flag();
    let session = open_link(&config, &suite)?;
    let routes: Vec<Route> = config
        .routes()?
        .into_iter()
        .map(|(topic, direction, rate)| Route {
            topic,
            direction: match direction {
                RouteDirection::ToZenoh => Direction::ToZenoh,
                RouteDirection::FromZenoh => Direction::FromZenoh,
            },
            max_rate_hz: rate,
            key: Some(link_key(&suite, topic)),
        })
        .collect();
    let bus = Bus::open(&names, &instance).context("opening the bus")?;
    let bridge = Bridge::start(&names, &session, &routes).context("starting the bridge")?;
    for r in &routes {
        tracing::info!(topic = r.topic.as_str(), direction = ?r.direction, key = r.zenoh_key(&names), "route");
    }
    if config.wait_for_link_s > 0.0 {
        let keys: Vec<String> = routes
            .iter()
            .filter(|r| r.direction == Direction::ToZenoh)
            .map(|r| r.zenoh_key(&names))
            .collect();
        let timeout = Duration::from_secs_f64(config.wait_for_link_s);
        wait_for_link(&session, &keys, timeout, &shutdown)?;
    }
    let heartbeat = Duration::from_millis(args.heartbeat_ms.max(1));
    let mut health = HealthReporter::new(&bus, &names, SERVICE, &instance, heartbeat)?;
    let stats_period = Duration::from_secs_f64(config.stats_period_s);
    let mut last_stats = Instant::now();
    let tick = heartbeat.min(Duration::from_millis(100));
    tracing::info!(
        prefix = names.prefix(),
        suite = suite.prefix(),
        instance,
        "bridge service running"
    );
    while !shutdown.load(Ordering::Relaxed) {
        std::thread::sleep(tick);
        let counters = counters(&bridge);
        let state = if bridge.is_running() {
            ServiceState::Running
        } else {
            ServiceState::Degraded
        };
        health.tick(&counters, state as u8)?;
        if last_stats.elapsed() >= stats_period {
            last_stats = Instant::now();
            write_stats(&config, &bridge, &routes);
        }
    }
    tracing::info!("bridge service stopping");
    write_stats(&config, &bridge, &routes);
    health.send(&counters(&bridge), ServiceState::Stopping as u8)?;
    bridge.stop().context("stopping the bridge")?;
    Ok(())
}

fn counters(bridge: &Bridge) -> Counters {
    let s = bridge.stats();
    Counters {
        frames_in: s.forwarded_from_zenoh,
        frames_out: s.forwarded_to_zenoh,
        rejected_wire: s.rejected_wire,
        errors: s.errors,
        ..Counters::default()
    }
}

/// Writes the counters and the per-topic link latencies as JSON.
fn write_stats(config: &BridgeServiceConfig, bridge: &Bridge, routes: &[Route]) {
    let Some(path) = &config.stats_file else {
        return;
    };
    let s = bridge.stats();
    let latency: serde_json::Map<String, serde_json::Value> = routes
        .iter()
        .filter(|r| r.direction == Direction::FromZenoh)
        .map(|r| {
            let l = bridge.link_latency(r.topic);
            let v = serde_json::json!({ "samples": l.samples, "mean_ms": l.mean_ms, "max_ms": l.max_ms });
            (r.topic.as_str().to_string(), v)
        })
        .collect();
    let json = serde_json::json!({
        "forwarded_to_zenoh": s.forwarded_to_zenoh,
        "forwarded_from_zenoh": s.forwarded_from_zenoh,
        "rejected_wire": s.rejected_wire,
        "rate_limited": s.rate_limited,
        "errors": s.errors,
        "latency_from_zenoh": latency,
        "routes": routes.iter().map(|r| format!("{} {:?}", r.topic.as_str(), r.direction)).collect::<Vec<_>>(),
    });
    let tmp = path.with_extension("tmp");
    let written = std::fs::write(&tmp, json.to_string()).and_then(|()| std::fs::rename(&tmp, path));
    if let Err(e) = written {
        tracing::warn!(path = %path.display(), "writing the bridge statistics: {e}");
    }
}
