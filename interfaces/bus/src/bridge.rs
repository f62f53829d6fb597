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

mod counters;
mod inbound;
mod limiter;
mod outbound;
mod route;
mod worker;

pub use counters::{BridgeStats, LinkLatency};
pub use route::{DEFAULT_CLOUD_RATE_HZ, Direction, Route};

use crate::error::BusError;
use counters::Counters;
use route::check_routes;
use spacepose_messages::{Names, Topic};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::Duration;
use worker::spawn;

/// How long [`Bridge::start`] waits for the workers to be ready.
const START_TIMEOUT: Duration = Duration::from_secs(10);

/// A running bridge; stops (and joins its workers) on [`Bridge::stop`] or drop.
#[derive(Debug)]
pub struct Bridge {
    stop: Arc<AtomicBool>,
    counters: Arc<Counters>,
    workers: Vec<JoinHandle<()>>,
    // Dropping these undeclares the zenoh subscribers.
    _zenoh_subscribers: Vec<zenoh::pubsub::Subscriber<()>>,
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
