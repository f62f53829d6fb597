//! `spacepose ground`: the ground tool. Subscribes over zenoh to the JSON
//! telemetry keys (`spacepose/{prefix}/telemetry/*`), prints a table that
//! refreshes, and records every message as a JSON line on request.

use anyhow::{Context, Result, bail};
use serde_json::{Value, json};
use spacepose_bus::zenoh::Wait;
use spacepose_bus::{ZenohConfig, open_zenoh};
use spacepose_eval::table::{Table, num};
use spacepose_messages::realtime_ns;
use spacepose_messages::telemetry::{TelemetryErrors, TelemetryHealth, TelemetryPose};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Options of the ground tool.
#[derive(Debug, Clone)]
pub struct GroundOptions {
    /// Endpoints to connect to (a suite listening); retried in the background.
    pub connect: Vec<String>,
    /// Endpoints to listen on (for a suite that connects to the ground).
    pub listen: Vec<String>,
    /// Deployment prefix, or `*` for every deployment.
    pub prefix: String,
    /// Append every message to this file as JSON lines.
    pub record: Option<PathBuf>,
    /// Stop after this long.
    pub duration: Option<Duration>,
    /// Stop after this many pose messages.
    pub count: Option<u64>,
    /// Table refresh period (`None`: no table, only the final counts).
    pub refresh: Option<Duration>,
}

/// What the ground tool saw.
#[derive(Debug, Default)]
pub struct GroundState {
    /// Messages per key suffix (`pose`, `health`, ...).
    pub received: BTreeMap<String, u64>,
    /// Latest pose per (prefix, tracker instance).
    pub poses: BTreeMap<(String, String), TelemetryPose>,
    /// Latest errors per (prefix, tracker instance).
    pub errors: BTreeMap<(String, String), TelemetryErrors>,
    /// Latest heartbeat per (prefix, instance).
    pub health: BTreeMap<(String, String), TelemetryHealth>,
    /// Messages that were not valid JSON of the documented schema.
    pub malformed: u64,
}

/// Splits `spacepose/{prefix}/telemetry/{what}` into (prefix, what).
pub fn split_key(key: &str) -> Option<(&str, &str)> {
    let rest = key.strip_prefix("spacepose/")?;
    let (prefix, rest) = rest.split_once('/')?;
    let what = rest.strip_prefix("telemetry/")?;
    Some((prefix, what))
}

impl GroundState {
    /// Records one message; returns the parsed JSON (`Null` if malformed).
    pub fn on_message(&mut self, key: &str, payload: &[u8]) -> Value {
        let Some((prefix, what)) = split_key(key) else {
            self.malformed += 1;
            return Value::Null;
        };
        // `health/<instance>`: counted and shown as `health`.
        let what = what.split('/').next().unwrap_or(what);
        *self.received.entry(what.to_string()).or_insert(0) += 1;
        let Ok(value) = serde_json::from_slice::<Value>(payload) else {
            self.malformed += 1;
            return Value::Null;
        };
        let ok = match what {
            "pose" => insert(&mut self.poses, prefix, &value, |p: &TelemetryPose| {
                p.instance.clone()
            }),
            "errors" => insert(&mut self.errors, prefix, &value, |e: &TelemetryErrors| {
                e.instance.clone()
            }),
            "health" => insert(&mut self.health, prefix, &value, |h: &TelemetryHealth| {
                h.instance.clone()
            }),
            _ => true,
        };
        if !ok {
            self.malformed += 1;
        }
        value
    }

    /// Pose messages received.
    pub fn poses_received(&self) -> u64 {
        self.received.get("pose").copied().unwrap_or(0)
    }

    /// The live table: a summary line, then the pose table and the health
    /// table, each only once something of its kind has arrived.
    pub fn render(&self, elapsed: Duration) -> String {
        let mut s = self.summary_line(elapsed);
        if !self.poses.is_empty() {
            s.push_str(&self.pose_table().render());
        }
        if !self.health.is_empty() {
            s.push_str(&self.health_table().render());
        }
        s
    }

    /// "-- ground T s: key N, ... (malformed M)", newline included, with
    /// "nothing yet" in place of the counts before the first message.
    fn summary_line(&self, elapsed: Duration) -> String {
        let counts: Vec<String> = self
            .received
            .iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect();
        format!(
            "-- ground {:.1} s: {} (malformed {})\n",
            elapsed.as_secs_f64(),
            if counts.is_empty() {
                "nothing yet".to_string()
            } else {
                counts.join(", ")
            },
            self.malformed
        )
    }

    /// One row per (prefix, tracker): its latest pose next to the latest
    /// errors of the same tracker, if any.
    fn pose_table(&self) -> Table {
        let mut t = Table::new(&POSE_COLUMNS);
        for ((prefix, inst), p) in &self.poses {
            let e = self.errors.get(&(prefix.clone(), inst.clone()));
            t.row(pose_row(prefix, inst, p, e));
        }
        t
    }

    /// One row per (prefix, instance): its latest heartbeat.
    fn health_table(&self) -> Table {
        let mut t = Table::new(&HEALTH_COLUMNS);
        for ((prefix, inst), h) in &self.health {
            t.row(health_row(prefix, inst, h));
        }
        t
    }
}

/// Column headers of the pose table, in the order of [`pose_row`].
const POSE_COLUMNS: [&str; 11] = [
    "prefix",
    "tracker",
    "frame",
    "status",
    "yaw deg",
    "pitch deg",
    "roll deg",
    "range m",
    "ang err deg",
    "pos err cm",
    "latency ms",
];

/// Column headers of the health table, in the order of [`health_row`].
const HEALTH_COLUMNS: [&str; 9] = [
    "prefix",
    "instance",
    "service",
    "state",
    "in",
    "out",
    "rejected",
    "errors",
    "last frame",
];

/// The cells of one pose row: Euler angles to 0.1°, range to the target in
/// metres, and `-` for errors not received yet or an unknown latency.
fn pose_row(
    prefix: &str,
    inst: &str,
    p: &TelemetryPose,
    e: Option<&TelemetryErrors>,
) -> Vec<String> {
    let range = p
        .p_sensor_target_m
        .iter()
        .map(|x| x * x)
        .sum::<f64>()
        .sqrt();
    vec![
        prefix.to_string(),
        inst.to_string(),
        p.sequence.to_string(),
        p.status.clone(),
        num(p.euler_321_deg[0], 1),
        num(p.euler_321_deg[1], 1),
        num(p.euler_321_deg[2], 1),
        num(range, 2),
        e.map_or("-".into(), |e| num(e.ang_err_deg, 2)),
        e.map_or("-".into(), |e| num(e.pos_err_cm, 2)),
        p.latency_ms.map_or("-".into(), |l| num(l, 2)),
    ]
}

/// The cells of one health row; "rejected" sums the frames rejected for
/// any reason (non-finite points, empty, oversized, refused by the codec).
fn health_row(prefix: &str, inst: &str, h: &TelemetryHealth) -> Vec<String> {
    let c = &h.counters;
    vec![
        prefix.to_string(),
        inst.to_string(),
        h.service.clone(),
        h.state.clone(),
        c.frames_in.to_string(),
        c.frames_out.to_string(),
        c.rejected().to_string(),
        c.errors.to_string(),
        c.last_frame.to_string(),
    ]
}

/// A flag set by SIGINT or SIGTERM, so the tool ends with its final table.
fn stop_flag() -> std::sync::Arc<std::sync::atomic::AtomicBool> {
    let flag = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        let _ = signal_hook::flag::register(signal, std::sync::Arc::clone(&flag));
    }
    flag
}

fn insert<T: serde::de::DeserializeOwned>(
    map: &mut BTreeMap<(String, String), T>,
    prefix: &str,
    value: &Value,
    instance: impl Fn(&T) -> String,
) -> bool {
    match serde_json::from_value::<T>(value.clone()) {
        Ok(v) => {
            map.insert((prefix.to_string(), instance(&v)), v);
            true
        }
        Err(_) => false,
    }
}

/// Runs the ground tool until `count` poses, `duration`, or Ctrl-C.
pub fn run(opts: &GroundOptions, out: &mut dyn Write) -> Result<GroundState> {
    if opts.prefix != "*" {
        spacepose_messages::names::validate_prefix(&opts.prefix)?;
    }
    if opts.connect.is_empty() && opts.listen.is_empty() {
        bail!("give at least one --connect or --listen endpoint");
    }
    let config = ZenohConfig {
        mode: "peer".to_string(),
        listen: opts.listen.clone(),
        connect: opts.connect.clone(),
        multicast_scouting: false,
    };
    let session = open_zenoh(&config).context("opening the zenoh session")?;
    let key = format!("spacepose/{}/telemetry/**", opts.prefix);
    let subscriber = session
        .declare_subscriber(&key)
        .wait()
        .map_err(|e| anyhow::anyhow!("subscribing to {key}: {e}"))?;
    let mut record = match &opts.record {
        Some(p) => Some(
            std::fs::File::options()
                .create(true)
                .append(true)
                .open(p)
                .with_context(|| format!("cannot open {}", p.display()))?,
        ),
        None => None,
    };
    let stop = stop_flag();
    writeln!(
        out,
        "ground: subscribed to {key} (connect {:?}, listen {:?})",
        opts.connect, opts.listen
    )?;
    let start = Instant::now();
    let mut last_table = Instant::now();
    let mut state = GroundState::default();
    loop {
        if opts.count.is_some_and(|n| state.poses_received() >= n) {
            break;
        }
        if opts.duration.is_some_and(|d| start.elapsed() >= d) {
            break;
        }
        if stop.load(std::sync::atomic::Ordering::Relaxed) {
            break;
        }
        let sample = subscriber
            .recv_timeout(Duration::from_millis(100))
            .map_err(|e| anyhow::anyhow!("receiving: {e}"))?;
        if let Some(sample) = sample {
            let key = sample.key_expr().as_str().to_string();
            let payload = sample.payload().to_bytes();
            let value = state.on_message(&key, &payload);
            if let Some(f) = record.as_mut() {
                let line = json!({ "key": key, "received_ns": realtime_ns(), "payload": value });
                writeln!(f, "{line}")?;
            }
        }
        if opts.refresh.is_some_and(|r| last_table.elapsed() >= r) {
            write!(out, "{}", state.render(start.elapsed()))?;
            last_table = Instant::now();
        }
    }
    write!(out, "{}", state.render(start.elapsed()))?;
    if let Some(n) = opts.count
        && state.poses_received() < n
    {
        bail!(
            "received {} of {n} pose messages within {:.1} s",
            state.poses_received(),
            start.elapsed().as_secs_f64()
        );
    }
    Ok(state)
}

#[cfg(test)]
#[path = "ground_tests.rs"]
mod tests;
