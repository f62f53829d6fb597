//! Watching the `health` topic of a deployment over iceoryx2.

use anyhow::{Context, Result};
use spacepose_bus::{Bus, Subscriber, Waiter, WakeReason};
use spacepose_messages::{Health, Names};
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

/// The latest heartbeat of every instance seen.
pub struct HealthWatch {
    subscriber: Subscriber<Health>,
    waiter: Waiter,
    latest: BTreeMap<String, Health>,
    received: BTreeMap<String, Instant>,
}

impl std::fmt::Debug for HealthWatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HealthWatch")
            .field("seen", &self.latest.len())
            .finish()
    }
}

impl HealthWatch {
    /// Subscribes to the health topic of `names` on `bus`.
    pub fn new(bus: &Bus, names: &Names) -> Result<Self> {
        let subscriber = bus
            .subscriber::<Health>(&names.health())
            .context("subscribing to the health topic")?;
        let mut waiter = bus.waitset_without_signals()?;
        waiter.attach(&subscriber)?;
        Ok(Self {
            subscriber,
            waiter,
            latest: BTreeMap::new(),
            received: BTreeMap::new(),
        })
    }

    /// Waits up to `timeout` for heartbeats and records them; returns how
    /// many arrived.
    pub fn poll(&mut self, timeout: Duration) -> Result<usize> {
        let reason = self.waiter.wait(timeout)?;
        if reason == WakeReason::TerminationRequested {
            anyhow::bail!("interrupted");
        }
        self.drain()
    }

    /// Records every buffered heartbeat without waiting.
    pub fn drain(&mut self) -> Result<usize> {
        let mut n = 0;
        while let Some(h) = self.subscriber.try_recv()? {
            let name = h.instance.as_str().to_string();
            self.received.insert(name.clone(), Instant::now());
            self.latest.insert(name, h);
            n += 1;
        }
        Ok(n)
    }

    /// Collects heartbeats for `period`.
    pub fn collect_for(&mut self, period: Duration) -> Result<()> {
        let end = Instant::now() + period;
        while let Some(left) = end.checked_duration_since(Instant::now()) {
            self.poll(left.min(Duration::from_millis(100)))?;
        }
        Ok(())
    }

    /// The latest heartbeat of `instance`.
    pub fn get(&self, instance: &str) -> Option<&Health> {
        self.latest.get(instance)
    }

    /// When the latest heartbeat of `instance` was received (this clock).
    pub fn received_at(&self, instance: &str) -> Option<Instant> {
        self.received.get(instance).copied()
    }

    /// Every instance seen, by name.
    pub fn all(&self) -> &BTreeMap<String, Health> {
        &self.latest
    }
}
