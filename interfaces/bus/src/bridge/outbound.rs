//! iceoryx2 -> zenoh worker.

use super::counters::Counters;
use super::limiter::Limiter;
use super::route::Route;
use super::worker::{Run, STOP_POLL};
use crate::cloud::CloudSubscriber;
use crate::error::BusError;
use crate::node::Bus;
use crate::pubsub::{Msg, Subscriber};
use crate::waiter::{Waiter, WakeReason};
use spacepose_messages::{
    AcquisitionResult, Command, FilterState, Health, Names, PoseEstimate, Topic, TruthMsg, encode,
};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use zenoh::Wait;
use zenoh::qos::CongestionControl;

type ZPublisher = zenoh::pubsub::Publisher<'static>;

/// One forwarded topic.
trait Forward {
    fn attach(&self, waiter: &mut Waiter) -> Result<usize, BusError>;
    fn drain(&mut self, counters: &Counters) -> Result<(), BusError>;
}

struct FixedOut<T: Msg> {
    sub: Subscriber<T>,
    publisher: ZPublisher,
    limiter: Limiter,
}

fn put(publisher: &ZPublisher, bytes: Vec<u8>, counters: &Counters) {
    match publisher.put(bytes).wait() {
        Ok(()) => Counters::bump(&counters.forwarded_to_zenoh),
        Err(e) => {
            Counters::bump(&counters.errors);
            tracing::warn!(key = %publisher.key_expr(), error = %e, "zenoh put failed");
        }
    }
}

impl<T: Msg> Forward for FixedOut<T> {
    fn attach(&self, waiter: &mut Waiter) -> Result<usize, BusError> {
        waiter.attach(&self.sub)
    }

    fn drain(&mut self, counters: &Counters) -> Result<(), BusError> {
        while let Some(msg) = self.sub.try_recv()? {
            if !self.limiter.allow(Instant::now()) {
                Counters::bump(&counters.rate_limited);
                continue;
            }
            match encode(&msg) {
                Ok(bytes) => put(&self.publisher, bytes, counters),
                Err(e) => {
                    Counters::bump(&counters.errors);
                    tracing::warn!(service = %self.sub.service(), error = %e, "local sample refused by the codec");
                }
            }
        }
        Ok(())
    }
}

struct CloudOut {
    sub: CloudSubscriber,
    publisher: ZPublisher,
    limiter: Limiter,
}

impl Forward for CloudOut {
    fn attach(&self, waiter: &mut Waiter) -> Result<usize, BusError> {
        waiter.attach(&self.sub)
    }

    fn drain(&mut self, counters: &Counters) -> Result<(), BusError> {
        while let Some(sample) = self.sub.try_recv()? {
            if !self.limiter.allow(Instant::now()) {
                Counters::bump(&counters.rate_limited);
                continue;
            }
            match encode(&sample.to_msg()) {
                Ok(bytes) => put(&self.publisher, bytes, counters),
                Err(e) => {
                    Counters::bump(&counters.errors);
                    tracing::warn!(service = %self.sub.service(), error = %e, "local cloud refused by the codec");
                }
            }
        }
        Ok(())
    }
}

fn declare(session: &zenoh::Session, key: String, cloud: bool) -> Result<ZPublisher, BusError> {
    // Clouds may be dropped under congestion; small messages block briefly instead.
    let congestion = if cloud {
        CongestionControl::Drop
    } else {
        CongestionControl::Block
    };
    session
        .declare_publisher(key.clone())
        .congestion_control(congestion)
        .express(!cloud)
        .wait()
        .map_err(|e| BusError::Zenoh(format!("declaring publisher {key}: {e}")))
}

fn fixed<T: Msg>(
    bus: &Bus,
    session: &zenoh::Session,
    route: &Route,
) -> Result<Box<dyn Forward>, BusError> {
    let names = bus.names();
    Ok(Box::new(FixedOut::<T> {
        sub: bus.subscriber::<T>(&names.service(route.topic))?,
        publisher: declare(session, route.zenoh_key(names), false)?,
        limiter: Limiter::new(route.min_interval()),
    }))
}

fn forwarder(
    bus: &Bus,
    session: &zenoh::Session,
    route: &Route,
) -> Result<Box<dyn Forward>, BusError> {
    match route.topic {
        Topic::RawCloud | Topic::Cloud => {
            let names = bus.names();
            Ok(Box::new(CloudOut {
                sub: bus.cloud_subscriber(&names.service(route.topic))?,
                publisher: declare(session, route.zenoh_key(names), true)?,
                limiter: Limiter::new(route.min_interval()),
            }))
        }
        Topic::Pose => fixed::<PoseEstimate>(bus, session, route),
        Topic::FilterState => fixed::<FilterState>(bus, session, route),
        Topic::Acquisition => fixed::<AcquisitionResult>(bus, session, route),
        Topic::Truth => fixed::<TruthMsg>(bus, session, route),
        Topic::Health => fixed::<Health>(bus, session, route),
        Topic::Command => fixed::<Command>(bus, session, route),
    }
}

/// The worker's node, forwarders and waiter (the node must outlive the ports).
type Ports = (Bus, Vec<Box<dyn Forward>>, Waiter);

/// The outbound worker's inputs (everything `Send`; ports are made in the thread).
pub(crate) struct Worker {
    names: Names,
    session: zenoh::Session,
    routes: Vec<Route>,
    stop: Arc<AtomicBool>,
    counters: Arc<Counters>,
}

impl Worker {
    pub(crate) fn new(
        names: &Names,
        session: &zenoh::Session,
        routes: Vec<Route>,
        stop: &Arc<AtomicBool>,
        counters: &Arc<Counters>,
    ) -> Self {
        Self {
            names: names.clone(),
            session: session.clone(),
            routes,
            stop: stop.clone(),
            counters: counters.clone(),
        }
    }

    fn setup(&self) -> Result<Ports, BusError> {
        let bus = Bus::open(&self.names, "bridge-out")?;
        let forwarders = self
            .routes
            .iter()
            .map(|r| forwarder(&bus, &self.session, r))
            .collect::<Result<Vec<_>, _>>()?;
        let mut waiter = bus.waitset_without_signals()?;
        for f in &forwarders {
            f.attach(&mut waiter)?;
        }
        Ok((bus, forwarders, waiter))
    }

    pub(crate) fn into_run(self) -> Run {
        Box::new(move |ready| {
            let (_bus, mut forwarders, mut waiter) = match self.setup() {
                Ok(v) => v,
                Err(e) => return ready(Err(e)),
            };
            ready(Ok(()));
            while !self.stop.load(Ordering::Relaxed) {
                match waiter.wait(STOP_POLL) {
                    Ok(WakeReason::Notified) => {
                        for &i in waiter.fired() {
                            if let Err(e) = forwarders[i].drain(&self.counters) {
                                Counters::bump(&self.counters.errors);
                                tracing::warn!(error = %e, "bridge receive failed");
                            }
                        }
                    }
                    Ok(_) => {}
                    Err(e) => {
                        Counters::bump(&self.counters.errors);
                        tracing::warn!(error = %e, "bridge wait failed");
                        std::thread::sleep(Duration::from_millis(10));
                    }
                }
            }
        })
    }
}
