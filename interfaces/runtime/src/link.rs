//! The zenoh side of a node that has one: the ground link of telemetry
//! (JSON streams, the `latest` queryable, the command route) and the host
//! link of the bridge (postcard routes between hosts).
//!
//! A node asks for it with [`crate::Node::link`]; the runtime opens it
//! before the bus and stops it last.

use anyhow::Context;
use spacepose_bus::zenoh::bytes::Encoding;
use spacepose_bus::zenoh::{self, Wait};
use spacepose_bus::{
    AccessControl, Bridge, BridgeStats, Credentials, Direction, LinkLatency, Route, ZenohConfig,
    open_zenoh_with,
};
use spacepose_messages::{Names, Topic};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Who may use the link (usrpwd accounts, an ACL by user name, default
/// deny; see `spacepose_bus::zenoh_access` and `docs/security.md`).
#[derive(Debug, Clone)]
pub enum Access {
    /// The ground link: readers read telemetry, operators also command.
    Ground(AccessControl),
    /// A host link of a partitioned suite `suite`: its peers exchange the
    /// suite's link keys. Enforced only where the host listens.
    Link(AccessControl, Names),
}

/// The zenoh link a node needs.
#[derive(Debug, Clone, Default)]
pub struct LinkSpec {
    /// Session mode and endpoints.
    pub zenoh: ZenohConfig,
    /// Access control; `None` lets anyone who reaches the endpoints in (a
    /// warning is logged when they are not loopback).
    pub access: Option<Access>,
    /// The account this end presents when it connects.
    pub credentials: Option<Credentials>,
    /// Topics forwarded between the bus and zenoh.
    pub routes: Vec<Route>,
    /// Telemetry key of a queryable answered with [`crate::Node::latest_json`].
    pub latest_key: Option<String>,
    /// Before the loop, wait this long at most for a subscriber on every
    /// outbound route (the consuming hosts); fail after it.
    pub wait_for_link: Option<Duration>,
}

/// The link's forwarding figures, for the node's counters and reports.
#[derive(Debug, Clone, Default)]
pub struct LinkStatus {
    /// Forwarded, refused and dropped samples since the start.
    pub stats: BridgeStats,
    /// Transit times of the inbound routes.
    pub latency: Vec<(Topic, LinkLatency)>,
    /// False once the forwarding threads stopped (true for a link without
    /// routes: nothing to stop).
    pub running: bool,
    /// The routes, as configured.
    pub routes: Vec<Route>,
}

/// An open link.
pub(crate) struct Link {
    session: zenoh::Session,
    names: Names,
    publishers: HashMap<String, zenoh::pubsub::Publisher<'static>>,
    bridge: Option<Bridge>,
    latest: Option<(Arc<Mutex<String>>, zenoh::query::Queryable<()>)>,
    pub(crate) status: LinkStatus,
}

impl Link {
    /// Opens the session and declares the `latest` queryable.
    pub(crate) fn open(spec: &LinkSpec, names: &Names) -> anyhow::Result<Link> {
        let session = open_session(spec, names)?;
        let latest = match &spec.latest_key {
            Some(key) => Some(declare_latest(&session, &names.telemetry_key(key))?),
            None => None,
        };
        Ok(Link {
            session,
            names: names.clone(),
            publishers: HashMap::new(),
            bridge: None,
            latest,
            status: LinkStatus {
                routes: spec.routes.clone(),
                running: true,
                ..LinkStatus::default()
            },
        })
    }

    /// Starts the routes (once the bus is open) and waits for the
    /// consuming hosts when asked.
    pub(crate) fn start(
        &mut self,
        spec: &LinkSpec,
        shutdown: &dyn Fn() -> bool,
    ) -> anyhow::Result<()> {
        if spec.routes.is_empty() {
            return Ok(());
        }
        let bridge = Bridge::start(&self.names, &self.session, &spec.routes)
            .context("starting the routes")?;
        for r in &spec.routes {
            tracing::info!(topic = r.topic.as_str(), direction = ?r.direction, key = r.zenoh_key(&self.names), "route");
        }
        self.bridge = Some(bridge);
        self.refresh();
        if let Some(timeout) = spec.wait_for_link {
            let keys: Vec<String> = spec
                .routes
                .iter()
                .filter(|r| r.direction == Direction::ToZenoh)
                .map(|r| r.zenoh_key(&self.names))
                .collect();
            wait_for_subscribers(&self.session, &keys, timeout, shutdown)?;
        }
        Ok(())
    }

    /// Reads the routes' figures into [`Link::status`].
    pub(crate) fn refresh(&mut self) {
        if let Some(b) = &self.bridge {
            let s = &mut self.status;
            s.stats = b.stats();
            s.running = b.is_running();
            s.latency = s
                .routes
                .iter()
                .filter(|r| r.direction == Direction::FromZenoh)
                .map(|r| (r.topic, b.link_latency(r.topic)))
                .collect();
        }
    }

    /// Publishes JSON under the telemetry key `key`.
    pub(crate) fn publish_json(&mut self, key: &str, json: &str) -> anyhow::Result<()> {
        if !self.publishers.contains_key(key) {
            let full = self.names.telemetry_key(key);
            let p = self
                .session
                .declare_publisher(full.clone())
                .encoding(Encoding::APPLICATION_JSON)
                .wait()
                .map_err(|e| anyhow::anyhow!("declaring a zenoh publisher on {full}: {e}"))?;
            self.publishers.insert(key.to_string(), p);
        }
        match self.publishers.get(key) {
            Some(p) => p
                .put(json.to_string())
                .wait()
                .map_err(|e| anyhow::anyhow!("zenoh put on {key}: {e}")),
            None => Ok(()),
        }
    }

    /// What the `latest` queryable answers from now on.
    pub(crate) fn set_latest(&self, json: String) {
        if let Some((slot, _)) = &self.latest
            && let Ok(mut s) = slot.lock()
        {
            *s = json;
        }
    }

    /// Stops the routes.
    pub(crate) fn stop(self) -> anyhow::Result<()> {
        if let Some(b) = self.bridge {
            b.stop().context("stopping the routes")?;
        }
        Ok(())
    }
}

fn open_session(spec: &LinkSpec, names: &Names) -> anyhow::Result<zenoh::Session> {
    let z = &spec.zenoh;
    let listens = !z.listen.is_empty();
    match &spec.access {
        Some(Access::Ground(a)) => tracing::info!(
            operators = ?a.operators, readers = ?a.readers, peers = ?a.peers,
            "zenoh access control on: usrpwd accounts, ACL by username, default deny"
        ),
        Some(Access::Link(a, _)) if listens => tracing::info!(
            peers = ?a.peers,
            "link access control on: usrpwd accounts, ACL by user name, default deny"
        ),
        _ => {
            let exposed = z.non_loopback_listen();
            if !exposed.is_empty() {
                tracing::warn!(
                    ?exposed,
                    "listening beyond loopback WITHOUT access control: anyone who reaches \
                     these endpoints can read and inject suite traffic (add [access])"
                );
            }
        }
    }
    open_zenoh_with(z, |c| {
        if let Some(creds) = &spec.credentials {
            creds.apply(c)?;
        }
        match &spec.access {
            Some(Access::Ground(a)) => a.apply(names, c),
            Some(Access::Link(a, suite)) if listens => a.apply_link(suite, c),
            _ => Ok(()),
        }
    })
    .context("opening zenoh")
}

fn declare_latest(
    session: &zenoh::Session,
    key: &str,
) -> anyhow::Result<(Arc<Mutex<String>>, zenoh::query::Queryable<()>)> {
    let slot = Arc::new(Mutex::new(String::from("{}")));
    let reply = Arc::clone(&slot);
    let reply_key = key.to_string();
    let q = session
        .declare_queryable(key.to_string())
        .callback(move |query| {
            let json = match reply.lock() {
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
        .map_err(|e| anyhow::anyhow!("declaring the queryable {key}: {e}"))?;
    Ok((slot, q))
}

/// Waits until every key has a subscriber, or fails after `timeout`.
fn wait_for_subscribers(
    session: &zenoh::Session,
    keys: &[String],
    timeout: Duration,
    shutdown: &dyn Fn() -> bool,
) -> anyhow::Result<()> {
    let publishers = keys
        .iter()
        .map(|k| session.declare_publisher(k.clone()).wait())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| anyhow::anyhow!("declaring a publisher: {e}"))?;
    let start = Instant::now();
    loop {
        let missing: Vec<&str> = publishers
            .iter()
            .zip(keys)
            .filter(|(p, _)| !p.matching_status().wait().is_ok_and(|m| m.matching()))
            .map(|(_, k)| k.as_str())
            .collect();
        if missing.is_empty() {
            tracing::info!(
                ms = start.elapsed().as_millis() as u64,
                "every outbound topic has a subscriber on the link"
            );
            return Ok(());
        }
        if start.elapsed() >= timeout || shutdown() {
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
