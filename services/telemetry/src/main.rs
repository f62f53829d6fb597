//! `spacepose-telemetry`: the suite seen from the ground.
//!
//! Subscribes to pose estimates, filter states, health and (simulated
//! sources) truth on iceoryx2, and publishes them as JSON on zenoh under
//! `spacepose/{prefix}/telemetry/`, with the errors against truth and a
//! queryable `latest`. Logic: [`TelemetryHub`]; schema: `TELEMETRY.md`.
//!
//! It also hosts the ground -> suite command path: a [`Bridge`] forwards
//! postcard `Command`s from `spacepose/{prefix}/wire/command` to the
//! iceoryx2 command topic; payloads the codec refuses are counted in this
//! service's `rejected_wire` health counter.
//!
//! Security: with an `[access]` table the zenoh session requires a usrpwd
//! account from every connecting peer and enforces an ACL by username
//! (readers: telemetry only; operators: telemetry and commands; default
//! deny), so only operators' commands ever reach the bridge. Without it,
//! anyone who reaches the endpoints may command the suite: the endpoints are
//! loopback by default, and listening elsewhere without `[access]` is
//! warned about. Why usernames (not TLS certificates, interfaces or zenoh
//! ids): `spacepose_bus::zenoh_access` and `deploy/SECURITY.md`.

use anyhow::Context;
use clap::Parser;
use serde::Deserialize;
use spacepose_bus::zenoh::Wait;
use spacepose_bus::zenoh::bytes::Encoding;
use spacepose_bus::{
    AccessControl, Bridge, Bus, Msg, Route, Subscriber, WakeReason, ZenohConfig, open_zenoh_with,
    zenoh,
};
use spacepose_messages::{FilterState, Health, Names, PoseEstimate, ServiceState, Topic, TruthMsg};
use spacepose_service_kit::{
    Counters, HealthReporter, ServiceArgs, ServiceConfig, init_logging, load_config, shutdown_flag,
};
use spacepose_telemetry::hub::Stream;
use spacepose_telemetry::{
    AccessConfig, LATEST_KEY, Output, RateLimiter, TelemetryConfig, TelemetryError, TelemetryHub,
};
use std::collections::HashMap;
use std::process::ExitCode;
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

const SERVICE: &str = "telemetry";

/// The service configuration as a TOML file ([`TelemetryConfig`]).
#[derive(Debug, Default, Deserialize)]
#[serde(transparent)]
struct Config(TelemetryConfig);

impl ServiceConfig for Config {
    fn validate(&self) -> Result<(), String> {
        self.0.validate().map_err(|e| e.to_string())?;
        // The accounts and the dictionary are checked too (`--check`).
        match &self.0.access {
            Some(a) => access_control(a).validate().map_err(|e| e.to_string()),
            None => Ok(()),
        }
    }
}

fn access_control(a: &AccessConfig) -> AccessControl {
    AccessControl {
        dictionary_file: a.dictionary_file.clone(),
        operators: a.operators.clone(),
        readers: a.readers.clone(),
        peers: a.peers.clone(),
    }
}

/// Opens the ground-link session, with the access control if configured.
fn open_ground_session(config: &TelemetryConfig, names: &Names) -> anyhow::Result<zenoh::Session> {
    let zenoh = zenoh_config(config);
    let access = config.access.as_ref().map(access_control);
    match &access {
        Some(a) => tracing::info!(
            operators = ?a.operators,
            readers = ?a.readers,
            peers = ?a.peers,
            "zenoh access control on: usrpwd accounts, ACL by username, default deny"
        ),
        None => {
            let exposed = zenoh.non_loopback_listen();
            if !exposed.is_empty() {
                tracing::warn!(
                    ?exposed,
                    "listening beyond loopback WITHOUT access control: anyone who reaches \
                     these endpoints can read telemetry and send commands (add [access])"
                );
            }
        }
    }
    open_zenoh_with(&zenoh, |c| match &access {
        Some(a) => a.apply(names, c),
        None => Ok(()),
    })
    .context("opening zenoh")
}

fn main() -> ExitCode {
    match run(ServiceArgs::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!("{e:#}");
            eprintln!("spacepose-telemetry: {e:#}");
            ExitCode::FAILURE
        }
    }
}

struct Ports {
    poses: Subscriber<PoseEstimate>,
    states: Subscriber<FilterState>,
    health: Subscriber<Health>,
    truth: Subscriber<TruthMsg>,
}

/// zenoh side: one JSON publisher per key, declared on first use.
struct Ground {
    session: zenoh::Session,
    names: Names,
    publishers: HashMap<String, zenoh::pubsub::Publisher<'static>>,
    limiter: RateLimiter,
    rates: spacepose_telemetry::Rates,
}

impl Ground {
    fn publish(&mut self, o: &Output, counters: &mut Counters) {
        let hz = match o.stream {
            Stream::Pose => self.rates.pose_hz,
            Stream::Filter => self.rates.filter_hz,
            Stream::Health => self.rates.health_hz,
            Stream::Truth => self.rates.truth_hz,
            Stream::Errors => self.rates.errors_hz,
        };
        if !self.limiter.allow(&o.key, hz, Instant::now()) {
            return;
        }
        if !self.publishers.contains_key(&o.key) {
            let key = self.names.telemetry_key(&o.key);
            match self
                .session
                .declare_publisher(key.clone())
                .encoding(Encoding::APPLICATION_JSON)
                .wait()
            {
                Ok(p) => {
                    self.publishers.insert(o.key.clone(), p);
                }
                Err(e) => {
                    counters.errors += 1;
                    tracing::warn!(key, "declaring a zenoh publisher: {e}");
                    return;
                }
            }
        }
        if let Some(p) = self.publishers.get(&o.key) {
            match p.put(o.json.clone()).wait() {
                Ok(()) => counters.frames_out += 1,
                Err(e) => {
                    counters.errors += 1;
                    tracing::warn!(key = o.key, "zenoh put: {e}");
                }
            }
        }
    }
}

fn zenoh_config(c: &TelemetryConfig) -> ZenohConfig {
    ZenohConfig {
        mode: c.zenoh.mode.clone(),
        listen: c.zenoh.listen.clone(),
        connect: c.zenoh.connect.clone(),
        multicast_scouting: false,
    }
}

fn run(args: ServiceArgs) -> anyhow::Result<()> {
    init_logging(SERVICE);
    let Config(config) = load_config(args.config.as_deref())?;
    let names = Names::new(&args.prefix).context("deployment prefix")?;
    let instance = args.instance_or(SERVICE);
    let shutdown = shutdown_flag();
    let session = open_ground_session(&config, &names)?;
    let mut hub = TelemetryHub::new(names.prefix(), config.match_window);
    let latest = Arc::new(Mutex::new(hub.latest_json()?));
    let _queryable = declare_latest(&session, &names, Arc::clone(&latest))?;

    let bus = Bus::open(&names, &instance).context("opening the bus")?;
    let mut commands = CommandBridge::start(&names, &session)?;
    let ports = Ports {
        poses: bus.subscriber(&names.pose())?,
        states: bus.subscriber(&names.filter_state())?,
        health: bus.subscriber(&names.health())?,
        truth: bus.subscriber(&names.truth())?,
    };
    let heartbeat = Duration::from_millis(args.heartbeat_ms.max(1));
    let mut health = HealthReporter::new(&bus, &names, SERVICE, &instance, heartbeat)?;
    let mut waiter = bus.waitset()?;
    for attach in [
        waiter.attach(&ports.poses),
        waiter.attach(&ports.states),
        waiter.attach(&ports.health),
        waiter.attach(&ports.truth),
    ] {
        attach?;
    }
    let mut ground = Ground {
        session,
        names: names.clone(),
        publishers: HashMap::new(),
        limiter: RateLimiter::new(),
        rates: config.rates.clone(),
    };
    let mut counters = Counters::default();
    tracing::info!(prefix = names.prefix(), instance, listen = ?config.zenoh.listen, "telemetry service running");
    while !shutdown.load(Ordering::Relaxed) {
        if waiter.wait(heartbeat)? == WakeReason::TerminationRequested {
            break;
        }
        let mut go = |outs: Result<Vec<Output>, TelemetryError>, counters: &mut Counters| match outs
        {
            Ok(outs) => outs.iter().for_each(|o| ground.publish(o, counters)),
            Err(e) => {
                counters.rejected_wire += 1;
                tracing::warn!("message refused: {e}");
            }
        };
        drain(&ports.truth, &mut counters, |m, c| go(hub.on_truth(m), c));
        drain(&ports.poses, &mut counters, |m, c| {
            c.last_frame = m.sequence;
            go(hub.on_pose(m), c);
        });
        drain(&ports.states, &mut counters, |m, c| go(hub.on_filter(m), c));
        drain(&ports.health, &mut counters, |m, c| go(hub.on_health(m), c));
        commands.report(&mut counters);
        match (hub.latest_json(), latest.lock()) {
            (Ok(json), Ok(mut slot)) => *slot = json,
            _ => counters.errors += 1,
        }
        health.tick(&counters, ServiceState::Running as u8)?;
    }
    tracing::info!("telemetry service stopping");
    commands.report(&mut counters);
    health.send(&counters, ServiceState::Stopping as u8)?;
    commands
        .bridge
        .stop()
        .context("stopping the command bridge")?;
    Ok(())
}

/// The zenoh -> iceoryx2 command path, and how much of its counters this
/// service has already reported.
struct CommandBridge {
    bridge: Bridge,
    rejected_seen: u64,
    stopped_seen: bool,
}

impl CommandBridge {
    fn start(names: &Names, session: &zenoh::Session) -> anyhow::Result<CommandBridge> {
        let bridge = Bridge::start(names, session, &[Route::from_zenoh(Topic::Command)])
            .context("starting the zenoh -> iceoryx2 command bridge")?;
        tracing::info!(
            key = names.wire_key(Topic::Command),
            "accepting commands from zenoh"
        );
        Ok(CommandBridge {
            bridge,
            rejected_seen: 0,
            stopped_seen: false,
        })
    }

    /// Adds the payloads the bridge refused since the last call to
    /// `counters.rejected_wire` (one warning per batch; the bridge itself
    /// logs each one), and counts a stopped bridge once as an error.
    fn report(&mut self, counters: &mut Counters) {
        let stats = self.bridge.stats();
        let new = stats.rejected_wire.saturating_sub(self.rejected_seen);
        if new > 0 {
            self.rejected_seen = stats.rejected_wire;
            counters.rejected_wire += new;
            tracing::warn!(
                new,
                total = stats.rejected_wire,
                "zenoh command payloads rejected (garbage, wrong schema version or kind)"
            );
        }
        if !self.stopped_seen && !self.bridge.is_running() {
            self.stopped_seen = true;
            counters.errors += 1;
            tracing::error!("the command bridge stopped: zenoh commands are no longer forwarded");
        }
    }
}

/// Drains `sub`, handing every message to `handle`; receive errors are counted.
fn drain<T: Msg>(
    sub: &Subscriber<T>,
    counters: &mut Counters,
    mut handle: impl FnMut(&T, &mut Counters),
) {
    loop {
        match sub.try_recv() {
            Ok(Some(m)) => {
                counters.frames_in += 1;
                handle(&m, counters);
            }
            Ok(None) => return,
            Err(e) => {
                counters.errors += 1;
                tracing::warn!(service = sub.service(), "receiving: {e}");
                return;
            }
        }
    }
}

/// The queryable `spacepose/{prefix}/telemetry/latest`: replies with the
/// latest state as one JSON object.
fn declare_latest(
    session: &zenoh::Session,
    names: &Names,
    latest: Arc<Mutex<String>>,
) -> anyhow::Result<zenoh::query::Queryable<()>> {
    let key = names.telemetry_key(LATEST_KEY);
    let reply_key = key.clone();
    session
        .declare_queryable(key.clone())
        .callback(move |query| {
            let json = match latest.lock() {
                Ok(json) => json.clone(),
                Err(_) => return,
            };
            if let Err(e) = query
                .reply(reply_key.clone(), json)
                .encoding(Encoding::APPLICATION_JSON)
                .wait()
            {
                tracing::warn!("replying to a latest query: {e}");
            }
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("declaring the queryable {key}: {e}"))
}
