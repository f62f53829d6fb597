//! The health heartbeat.

use anyhow::Context;
use spacepose_bus::{Bus, Publisher};
use spacepose_messages::{Counters, Health, Name, Names, ServiceState, realtime_ns};
use std::time::{Duration, Instant};

/// Publishes a [`Health`] message on the health topic at most every `every`.
#[derive(Debug)]
pub struct HealthReporter {
    publisher: Publisher<Health>,
    health: Health,
    every: Duration,
    started: Instant,
    last_sent: Option<Instant>,
}

impl HealthReporter {
    /// A reporter for `service`/`instance` on the health topic of `names`.
    ///
    /// # Errors
    /// Names longer than [`spacepose_messages::name::NAME_LEN`] bytes or not
    /// ASCII, or a bus error.
    pub fn new(
        bus: &Bus,
        names: &Names,
        service: &str,
        instance: &str,
        every: Duration,
    ) -> anyhow::Result<Self> {
        let service_name =
            Name::new(service).with_context(|| format!("service name {service:?}"))?;
        let instance_name =
            Name::new(instance).with_context(|| format!("instance name {instance:?}"))?;
        let publisher = bus
            .publisher::<Health>(&names.health())
            .context("opening the health publisher")?;
        Ok(HealthReporter {
            publisher,
            health: Health::new(service_name, instance_name, std::process::id()),
            every,
            started: Instant::now(),
            last_sent: None,
        })
    }

    /// Publishes when `every` has elapsed since the last heartbeat (or none
    /// was sent yet).
    pub fn tick(&mut self, counters: &Counters, state: u8) -> anyhow::Result<()> {
        let due = self.last_sent.is_none_or(|t| t.elapsed() >= self.every);
        if due {
            self.send(counters, state)?;
        }
        Ok(())
    }

    /// Publishes now (e.g. the `Stopping` heartbeat on the way out).
    pub fn send(&mut self, counters: &Counters, state: u8) -> anyhow::Result<()> {
        let h = &mut self.health;
        h.state = state.min(ServiceState::Stopping as u8);
        h.uptime_s = self.started.elapsed().as_secs_f64();
        h.counters = *counters;
        h.published_ns = realtime_ns();
        self.publisher.send(h).context("publishing health")?;
        h.sequence += 1;
        self.last_sent = Some(Instant::now());
        Ok(())
    }

    /// Heartbeats sent so far.
    pub fn sent(&self) -> u64 {
        self.health.sequence
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heartbeats_carry_the_counters_and_respect_the_period() {
        let prefix = format!("kit{}", std::process::id());
        let names = Names::new(&prefix).unwrap();
        let bus = Bus::open(&names, "kit-test").unwrap();
        let sub = bus.subscriber::<Health>(&names.health()).unwrap();
        let mut rep =
            HealthReporter::new(&bus, &names, "ingest", "ingest-a", Duration::from_secs(60))
                .unwrap();
        let counters = Counters {
            frames_in: 5,
            frames_out: 3,
            rejected_empty: 1,
            last_frame: 4,
            ..Counters::default()
        };
        rep.tick(&counters, ServiceState::Running as u8).unwrap();
        // Within the period: nothing more.
        rep.tick(&counters, ServiceState::Running as u8).unwrap();
        rep.send(&counters, ServiceState::Stopping as u8).unwrap();
        let first = sub.try_recv().unwrap().unwrap();
        assert_eq!(first.service.as_str(), "ingest");
        assert_eq!(first.instance.as_str(), "ingest-a");
        assert_eq!(
            (
                first.counters.frames_in,
                first.counters.frames_out,
                first.counters.rejected_empty
            ),
            (5, 3, 1)
        );
        assert_eq!((first.sequence, first.counters.last_frame), (0, 4));
        assert_eq!(first.state, ServiceState::Running as u8);
        assert_eq!(first.pid, std::process::id());
        let second = sub.try_recv().unwrap().unwrap();
        assert_eq!(
            (second.sequence, second.state),
            (1, ServiceState::Stopping as u8)
        );
        assert!(sub.try_recv().unwrap().is_none());
        assert_eq!(rep.sent(), 2);
        assert!(
            HealthReporter::new(
                &bus,
                &names,
                "a-service-name-that-is-too-long",
                "x",
                Duration::ZERO
            )
            .is_err()
        );
    }
}
