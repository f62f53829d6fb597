//! zenoh -> iceoryx2 worker.

use super::counters::Counters;
use super::limiter::Limiter;
use super::route::Route;
use super::worker::{Run, STOP_POLL};
use crate::cloud::CloudPublisher;
use crate::error::BusError;
use crate::node::Bus;
use crate::pubsub::{Msg, Publisher};
use spacepose_messages::{
    AcquisitionResult, CloudMsg, CodecError, Command, FilterState, Health, MAX_POINTS, Names,
    PoseEstimate, Topic, TruthMsg, decode, realtime_ns,
};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Instant;
use zenoh::Wait;

/// A payload received on the key of route `.0`.
pub(crate) type Incoming = (usize, Vec<u8>);

enum InjectError {
    Codec(CodecError),
    Bus(BusError),
}

/// One topic injected into iceoryx2.
trait Inject {
    /// Decodes and re-publishes; returns the sender's `published_ns` (0
    /// when the message carries none).
    fn inject(&mut self, bytes: &[u8]) -> Result<i64, InjectError>;
}

struct FixedIn<T: Msg> {
    publisher: Publisher<T>,
    sent_ns: fn(&T) -> i64,
}

impl<T: Msg> Inject for FixedIn<T> {
    fn inject(&mut self, bytes: &[u8]) -> Result<i64, InjectError> {
        let msg = decode::<T>(bytes).map_err(InjectError::Codec)?;
        self.publisher.send(&msg).map_err(InjectError::Bus)?;
        Ok((self.sent_ns)(&msg))
    }
}

struct CloudIn {
    publisher: CloudPublisher,
}

impl Inject for CloudIn {
    fn inject(&mut self, bytes: &[u8]) -> Result<i64, InjectError> {
        let msg = decode::<CloudMsg>(bytes).map_err(InjectError::Codec)?;
        self.publisher
            .send(msg.header, &msg.points)
            .map_err(InjectError::Bus)?;
        Ok(msg.header.published_ns)
    }
}

fn injector(bus: &Bus, topic: Topic) -> Result<Box<dyn Inject>, BusError> {
    let service = bus.names().service(topic);
    fn fixed<T: Msg>(
        bus: &Bus,
        service: &str,
        sent_ns: fn(&T) -> i64,
    ) -> Result<Box<dyn Inject>, BusError> {
        Ok(Box::new(FixedIn::<T> {
            publisher: bus.publisher::<T>(service)?,
            sent_ns,
        }))
    }
    match topic {
        Topic::RawCloud | Topic::Cloud => Ok(Box::new(CloudIn {
            publisher: bus.cloud_publisher(&service, MAX_POINTS)?,
        })),
        Topic::Pose => fixed::<PoseEstimate>(bus, &service, |m| m.published_ns),
        Topic::FilterState => fixed::<FilterState>(bus, &service, |m| m.published_ns),
        Topic::Acquisition => fixed::<AcquisitionResult>(bus, &service, |_| 0),
        Topic::Truth => fixed::<TruthMsg>(bus, &service, |_| 0),
        Topic::Health => fixed::<Health>(bus, &service, |m| m.published_ns),
        Topic::Command => fixed::<Command>(bus, &service, |_| 0),
    }
}

/// Declares one zenoh subscriber per route; payloads go to `tx` tagged with
/// the route index.
pub(crate) fn subscribe(
    names: &Names,
    session: &zenoh::Session,
    routes: &[Route],
    tx: mpsc::Sender<Incoming>,
) -> Result<Vec<zenoh::pubsub::Subscriber<()>>, BusError> {
    routes
        .iter()
        .enumerate()
        .map(|(i, route)| {
            let key = route.zenoh_key(names);
            let tx = tx.clone();
            session
                .declare_subscriber(key.clone())
                .callback(move |sample| {
                    // The worker may be gone during shutdown; dropping is fine then.
                    let _ = tx.send((i, sample.payload().to_bytes().into_owned()));
                })
                .wait()
                .map_err(|e| BusError::Zenoh(format!("declaring subscriber {key}: {e}")))
        })
        .collect()
}

/// The inbound worker's inputs.
pub(crate) struct Worker {
    names: Names,
    routes: Vec<Route>,
    rx: mpsc::Receiver<Incoming>,
    stop: Arc<AtomicBool>,
    counters: Arc<Counters>,
}

impl Worker {
    pub(crate) fn new(
        names: &Names,
        routes: Vec<Route>,
        rx: mpsc::Receiver<Incoming>,
        stop: &Arc<AtomicBool>,
        counters: &Arc<Counters>,
    ) -> Self {
        Self {
            names: names.clone(),
            routes,
            rx,
            stop: stop.clone(),
            counters: counters.clone(),
        }
    }

    fn setup(&self) -> Result<(Bus, Vec<Box<dyn Inject>>), BusError> {
        let bus = Bus::open(&self.names, "bridge-in")?;
        let injectors = self
            .routes
            .iter()
            .map(|r| injector(&bus, r.topic))
            .collect::<Result<Vec<_>, _>>()?;
        Ok((bus, injectors))
    }

    fn handle(&self, injectors: &mut [Box<dyn Inject>], limiters: &mut [Limiter], msg: Incoming) {
        let (i, bytes) = msg;
        let (Some(injector), Some(limiter)) = (injectors.get_mut(i), limiters.get_mut(i)) else {
            return;
        };
        if !limiter.allow(Instant::now()) {
            Counters::bump(&self.counters.rate_limited);
            return;
        }
        let topic = self.routes[i].topic.as_str();
        match injector.inject(&bytes) {
            Ok(sent_ns) => {
                Counters::bump(&self.counters.forwarded_from_zenoh);
                self.counters
                    .transit(self.routes[i].topic, sent_ns, realtime_ns());
            }
            Err(InjectError::Codec(e)) => {
                Counters::bump(&self.counters.rejected_wire);
                // Every rejection is counted; the log is throttled (the first
                // ten, then the 16th, 32nd, ...) so a flood of garbage cannot
                // flood the log as well.
                let n = self.counters.rejected_wire.load(Ordering::Relaxed);
                if n <= 10 || n.is_power_of_two() {
                    tracing::warn!(topic, len = bytes.len(), error = %e, rejected = n, "rejected zenoh payload");
                } else {
                    tracing::debug!(topic, len = bytes.len(), error = %e, rejected = n, "rejected zenoh payload");
                }
            }
            Err(InjectError::Bus(e)) => {
                Counters::bump(&self.counters.errors);
                tracing::warn!(topic, error = %e, "could not publish a bridged sample");
            }
        }
    }

    pub(crate) fn into_run(self) -> Run {
        Box::new(move |ready| {
            let (_bus, mut injectors) = match self.setup() {
                Ok(v) => v,
                Err(e) => return ready(Err(e)),
            };
            let mut limiters: Vec<Limiter> = self
                .routes
                .iter()
                .map(|r| Limiter::new(r.min_interval()))
                .collect();
            ready(Ok(()));
            while !self.stop.load(Ordering::Relaxed) {
                match self.rx.recv_timeout(STOP_POLL) {
                    Ok(msg) => self.handle(&mut injectors, &mut limiters, msg),
                    Err(mpsc::RecvTimeoutError::Timeout) => {}
                    Err(mpsc::RecvTimeoutError::Disconnected) => break,
                }
            }
        })
    }
}
