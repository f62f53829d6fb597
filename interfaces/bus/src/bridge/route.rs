//! The allow-list of a bridge: which topics go to zenoh and which come
//! back, with their rate limits and keys, and the check of that list.

use crate::error::BusError;
use spacepose_messages::{Names, Topic};
use std::time::Duration;

/// Default rate limit of clouds forwarded to zenoh (Hz).
pub const DEFAULT_CLOUD_RATE_HZ: f64 = 1.0;

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

    pub(crate) fn min_interval(&self) -> Option<Duration> {
        self.max_rate_hz
            .filter(|hz| hz.is_finite() && *hz > 0.0)
            .map(|hz| Duration::from_secs_f64(1.0 / hz))
    }
}

pub(crate) fn check_routes(routes: &[Route]) -> Result<(), BusError> {
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
