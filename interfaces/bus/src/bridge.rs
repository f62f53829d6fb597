//! The iceoryx2 <-> zenoh bridge (iceoryx2's own gateway is not published
//! for 0.10).
//!
//! An allow-list of [`Route`]s says which topics go to zenoh (postcard codec
//! on [`Names::wire_key`]) and which come back (typically commands). Clouds
//! are rate limited. Bytes on an inbound key that the codec refuses are
//! counted in [`BridgeStats::rejected_wire`], logged, and dropped: they never
//! reach iceoryx2 and never stop the bridge.
//!
//! Threads: one outbound worker (its own iceoryx2 node and WaitSet, woken by
//! the publishers' events) and one inbound worker (its own node, fed by the
//! zenoh subscriber callbacks through a channel). iceoryx2 ports of the
//! `ipc` flavour are not `Send`, so each worker opens its own node.

mod inbound;
mod limiter;
mod outbound;

use crate::error::BusError;
use spacepose_messages::{Names, Topic};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::Duration;

/// Default rate limit of clouds forwarded to zenoh (Hz).
pub const DEFAULT_CLOUD_RATE_HZ: f64 = 1.0;
/// How long the workers block before looking at the stop flag.
const STOP_POLL: Duration = Duration::from_millis(100);
/// How long [`Bridge::start`] waits for the workers to be ready.
const START_TIMEOUT: Duration = Duration::from_secs(10);

/// Which way a route forwards.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// iceoryx2 service -> zenoh key.
    ToZenoh,
    /// zenoh key -> iceoryx2 service.
    FromZenoh,
}

/// One allow-listed topic.
#[derive(Debug, Clone, PartialEq)]
pub struct Route {
    /// The topic (its iceoryx2 service is [`Names::service`]).
    pub topic: Topic,
    /// Direction of forwarding.
    pub direction: Direction,
    /// Largest forwarding rate (Hz); samples arriving faster are dropped and
    /// counted. `None` = unlimited.
    pub max_rate_hz: Option<f64>,
    /// zenoh key; `None` = [`Names::wire_key`] of the topic.
    pub key: Option<String>,
}

impl Route {
    /// Forward `topic` from iceoryx2 to zenoh (clouds limited to
    /// [`DEFAULT_CLOUD_RATE_HZ`]).
    pub fn to_zenoh(topic: Topic) -> Route {
        Route {
            topic,
            direction: Direction::ToZenoh,
            max_rate_hz: topic.is_cloud().then_some(DEFAULT_CLOUD_RATE_HZ),
            key: None,
        }
    }

    /// Forward `topic` from zenoh to iceoryx2.
    pub fn from_zenoh(topic: Topic) -> Route {
        Route {
            topic,
            direction: Direction::FromZenoh,
            max_rate_hz: topic.is_cloud().then_some(DEFAULT_CLOUD_RATE_HZ),
            key: None,
        }
    }

    /// Sets the rate limit (Hz; `None` = unlimited).
    pub fn with_rate(mut self, max_rate_hz: Option<f64>) -> Route {
        self.max_rate_hz = max_rate_hz;
        self
    }

    /// The zenoh key of the route.
    pub fn zenoh_key(&self, names: &Names) -> String {
        self.key
            .clone()
            .unwrap_or_else(|| names.wire_key(self.topic))
    }

    fn min_interval(&self) -> Option<Duration> {
        self.max_rate_hz
            .filter(|hz| hz.is_finite() && *hz > 0.0)
            .map(|hz| Duration::from_secs_f64(1.0 / hz))
    }
}

/// Counters of a running bridge.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BridgeStats {
    /// Samples forwarded iceoryx2 -> zenoh.
    pub forwarded_to_zenoh: u64,
    /// Samples forwarded zenoh -> iceoryx2.
    pub forwarded_from_zenoh: u64,
    /// zenoh payloads refused by the codec (garbage, wrong version or kind, oversized).
    pub rejected_wire: u64,
    /// Samples dropped by a rate limit.
    pub rate_limited: u64,
    /// Other failures (encoding a local sample, publishing, receiving).
    pub errors: u64,
}

/// Transit time of the samples a bridge took from zenoh on one topic: from
/// the sender's `published_ns` (stamped when it was published on the other
/// host's iceoryx2) to their re-publication here. Wall clock: meaningful
/// when the hosts' clocks are synchronised (one machine, or PTP/NTP);
/// samples that seem to arrive before they were sent are not counted.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LinkLatency {
    /// Samples measured.
    pub samples: u64,
    /// Mean transit time (ms).
    pub mean_ms: f64,
    /// Largest transit time (ms).
    pub max_ms: f64,
}

#[derive(Debug, Default)]
pub(crate) struct LatencySum {
    sum_us: AtomicU64,
    max_us: AtomicU64,
    samples: AtomicU64,
}

#[derive(Debug, Default)]
pub(crate) struct Counters {
    pub(crate) forwarded_to_zenoh: AtomicU64,
    pub(crate) forwarded_from_zenoh: AtomicU64,
    pub(crate) rejected_wire: AtomicU64,
    pub(crate) rate_limited: AtomicU64,
    pub(crate) errors: AtomicU64,
    /// Per topic, in the order of `Topic::ALL`.
    latency: [LatencySum; Topic::ALL.len()],
}

fn topic_index(topic: Topic) -> usize {
    Topic::ALL.iter().position(|t| *t == topic).unwrap_or(0)
}

impl Counters {
    pub(crate) fn bump(counter: &AtomicU64) {
        counter.fetch_add(1, Ordering::Relaxed);
    }

    /// Records the transit of a sample of `topic` sent at `sent_ns`
    /// (CLOCK_REALTIME) and re-published at `now_ns`.
    pub(crate) fn transit(&self, topic: Topic, sent_ns: i64, now_ns: i64) {
        if sent_ns <= 0 || now_ns < sent_ns {
            return;
        }
        let us = ((now_ns - sent_ns) / 1000) as u64;
        let l = &self.latency[topic_index(topic)];
        l.sum_us.fetch_add(us, Ordering::Relaxed);
        l.max_us.fetch_max(us, Ordering::Relaxed);
        l.samples.fetch_add(1, Ordering::Relaxed);
    }

    fn latency(&self, topic: Topic) -> LinkLatency {
        let l = &self.latency[topic_index(topic)];
        let samples = l.samples.load(Ordering::Relaxed);
        let sum_us = l.sum_us.load(Ordering::Relaxed);
        LinkLatency {
            samples,
            mean_ms: if samples == 0 {
                0.0
            } else {
                sum_us as f64 / samples as f64 / 1000.0
            },
            max_ms: l.max_us.load(Ordering::Relaxed) as f64 / 1000.0,
        }
    }

    fn snapshot(&self) -> BridgeStats {
        BridgeStats {
            forwarded_to_zenoh: self.forwarded_to_zenoh.load(Ordering::Relaxed),
            forwarded_from_zenoh: self.forwarded_from_zenoh.load(Ordering::Relaxed),
            rejected_wire: self.rejected_wire.load(Ordering::Relaxed),
            rate_limited: self.rate_limited.load(Ordering::Relaxed),
            errors: self.errors.load(Ordering::Relaxed),
        }
    }
}

/// A running bridge; stops (and joins its workers) on [`Bridge::stop`] or drop.
#[derive(Debug)]
pub struct Bridge {
    stop: Arc<AtomicBool>,
    counters: Arc<Counters>,
    workers: Vec<JoinHandle<()>>,
    // Dropping these undeclares the zenoh subscribers.
    _zenoh_subscribers: Vec<zenoh::pubsub::Subscriber<()>>,
}

fn check_routes(routes: &[Route]) -> Result<(), BusError> {
    for (i, a) in routes.iter().enumerate() {
        if routes[..i].iter().any(|b| b.topic == a.topic) {
            return Err(BusError::BridgeConfig(format!(
                "topic {} listed twice (a topic in both directions would loop)",
                a.topic.as_str()
            )));
        }
        if let Some(hz) = a.max_rate_hz
            && !(hz.is_finite() && hz > 0.0)
        {
            return Err(BusError::BridgeConfig(format!(
                "rate limit of {} must be a positive number of Hz, got {hz}",
                a.topic.as_str()
            )));
        }
    }
    Ok(())
}

impl Bridge {
    /// Starts forwarding `routes` of the deployment `names` over `session`.
    /// Returns once every port is created (samples sent after that are
    /// forwarded).
    pub fn start(
        names: &Names,
        session: &zenoh::Session,
        routes: &[Route],
    ) -> Result<Bridge, BusError> {
        check_routes(routes)?;
        let stop = Arc::new(AtomicBool::new(false));
        let counters = Arc::new(Counters::default());
        let (ready_tx, ready_rx) = mpsc::channel::<Result<(), BusError>>();
        let mut bridge = Bridge {
            stop: stop.clone(),
            counters: counters.clone(),
            workers: Vec::new(),
            _zenoh_subscribers: Vec::new(),
        };
        let out: Vec<Route> = routes
            .iter()
            .filter(|r| r.direction == Direction::ToZenoh)
            .cloned()
            .collect();
        let inb: Vec<Route> = routes
            .iter()
            .filter(|r| r.direction == Direction::FromZenoh)
            .cloned()
            .collect();
        let mut expected = 0;
        if !out.is_empty() {
            let worker = outbound::Worker::new(names, session, out, &stop, &counters);
            bridge
                .workers
                .push(spawn("bridge-out", ready_tx.clone(), worker.into_run())?);
            expected += 1;
        }
        if !inb.is_empty() {
            let (tx, rx) = mpsc::channel();
            bridge._zenoh_subscribers = inbound::subscribe(names, session, &inb, tx)?;
            let worker = inbound::Worker::new(names, inb, rx, &stop, &counters);
            bridge
                .workers
                .push(spawn("bridge-in", ready_tx.clone(), worker.into_run())?);
            expected += 1;
        }
        drop(ready_tx);
        for _ in 0..expected {
            match ready_rx.recv_timeout(START_TIMEOUT) {
                Ok(Ok(())) => {}
                Ok(Err(e)) => return Err(e),
                Err(e) => {
                    return Err(BusError::BridgeWorker(format!("not ready: {e}")));
                }
            }
        }
        Ok(bridge)
    }

    /// Current counters.
    pub fn stats(&self) -> BridgeStats {
        self.counters.snapshot()
    }

    /// Transit time of the samples of `topic` taken from zenoh so far.
    pub fn link_latency(&self, topic: Topic) -> LinkLatency {
        self.counters.latency(topic)
    }

    /// True while every worker thread is running.
    pub fn is_running(&self) -> bool {
        self.workers.iter().all(|w| !w.is_finished())
    }

    /// Stops the workers and waits for them.
    pub fn stop(mut self) -> Result<(), BusError> {
        self.shutdown()
    }

    fn shutdown(&mut self) -> Result<(), BusError> {
        self.stop.store(true, Ordering::Relaxed);
        let mut panicked = 0;
        for w in self.workers.drain(..) {
            if w.join().is_err() {
                panicked += 1;
            }
        }
        if panicked > 0 {
            return Err(BusError::BridgeWorker(format!(
                "{panicked} worker(s) panicked"
            )));
        }
        Ok(())
    }
}

impl Drop for Bridge {
    fn drop(&mut self) {
        if let Err(e) = self.shutdown() {
            tracing::error!(error = %e, "bridge shutdown");
        }
    }
}

/// A worker body: set up, report readiness once, then run until stopped.
pub(crate) type Run = Box<dyn FnOnce(&dyn Fn(Result<(), BusError>)) + Send>;

fn spawn(
    name: &str,
    ready: mpsc::Sender<Result<(), BusError>>,
    run: Run,
) -> Result<JoinHandle<()>, BusError> {
    std::thread::Builder::new()
        .name(name.to_string())
        .spawn(move || {
            let report = move |r: Result<(), BusError>| {
                // The starter may have given up already; nothing else to do then.
                let _ = ready.send(r);
            };
            run(&report)
        })
        .map_err(|e| BusError::BridgeWorker(format!("spawning {name}: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn routes_are_checked() {
        let ok = [
            Route::to_zenoh(Topic::Pose),
            Route::from_zenoh(Topic::Command),
        ];
        assert!(check_routes(&ok).is_ok());
        let twice = [
            Route::to_zenoh(Topic::Command),
            Route::from_zenoh(Topic::Command),
        ];
        assert!(matches!(
            check_routes(&twice),
            Err(BusError::BridgeConfig(_))
        ));
        let bad_rate = [Route::to_zenoh(Topic::Cloud).with_rate(Some(0.0))];
        assert!(matches!(
            check_routes(&bad_rate),
            Err(BusError::BridgeConfig(_))
        ));
        assert_eq!(
            Route::to_zenoh(Topic::Cloud).max_rate_hz,
            Some(DEFAULT_CLOUD_RATE_HZ)
        );
        assert_eq!(Route::to_zenoh(Topic::Pose).max_rate_hz, None);
        let c = Counters::default();
        c.transit(Topic::Pose, 1_000_000, 3_000_000);
        c.transit(Topic::Pose, 1_000_000, 5_000_000);
        c.transit(Topic::Pose, 5_000_000, 1_000_000); // clock skew: ignored
        c.transit(Topic::Cloud, 0, 1_000_000); // not stamped: ignored
        let l = c.latency(Topic::Pose);
        assert_eq!((l.samples, l.mean_ms, l.max_ms), (2, 3.0, 4.0));
        assert_eq!(c.latency(Topic::Cloud).samples, 0);
        assert_eq!(
            Route::to_zenoh(Topic::Pose)
                .with_rate(Some(4.0))
                .min_interval(),
            Some(Duration::from_millis(250))
        );
    }
}
