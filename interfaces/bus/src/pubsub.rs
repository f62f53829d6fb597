//! Publish-subscribe of fixed-size `#[repr(C)]` messages, each publisher
//! paired with an event notifier so subscribers wake without polling.

use crate::error::BusError;
use crate::node::Bus;
use crate::waiter::EventFactory;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher as IoxPublisher;
use iceoryx2::port::subscriber::Subscriber as IoxSubscriber;
use iceoryx2::prelude::*;
use spacepose_messages::{WireMessage, ZeroCopySend, realtime_ns};
use std::fmt::Debug;

pub use crate::waiter::Wakeable;

/// A fixed-size message of the suite: `#[repr(C)]`, `ZeroCopySend`, and in
/// the postcard codec (every message type of `spacepose-messages` is one).
pub trait Msg: Debug + Copy + ZeroCopySend + WireMessage + 'static {}

impl<T: Debug + Copy + ZeroCopySend + WireMessage + 'static> Msg for T {}

/// Publisher of one fixed-size message type.
pub struct Publisher<T: Msg> {
    service: String,
    publisher: IoxPublisher<ipc::Service, T, ()>,
    notifier: Notifier<ipc::Service>,
}

impl<T: Msg> Debug for Publisher<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Publisher")
            .field("service", &self.service)
            .finish()
    }
}

impl<T: Msg> Publisher<T> {
    /// Sends a copy of `msg`, with `published_ns` stamped now (where the type
    /// has one), then notifies the subscribers' waiters.
    pub fn send(&self, msg: &T) -> Result<(), BusError> {
        let mut msg = *msg;
        msg.set_published_ns(realtime_ns());
        self.publisher
            .send_copy(msg)
            .map_err(|e| BusError::send(&self.service, e))?;
        self.notifier
            .notify()
            .map_err(|e| BusError::send(&self.service, e))?;
        Ok(())
    }

    /// The service name.
    pub fn service(&self) -> &str {
        &self.service
    }
}

/// Subscriber of one fixed-size message type.
pub struct Subscriber<T: Msg> {
    service: String,
    subscriber: IoxSubscriber<ipc::Service, T, ()>,
    event: EventFactory,
}

impl<T: Msg> Debug for Subscriber<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Subscriber")
            .field("service", &self.service)
            .finish()
    }
}

impl<T: Msg> Subscriber<T> {
    /// The next buffered message, if any (never blocks).
    pub fn try_recv(&self) -> Result<Option<T>, BusError> {
        let sample = self
            .subscriber
            .receive()
            .map_err(|e| BusError::receive(&self.service, e))?;
        Ok(sample.map(|s| *s.payload()))
    }

    /// Drains the buffer and returns the newest message, if any.
    pub fn try_recv_latest(&self) -> Result<Option<T>, BusError> {
        let mut latest = None;
        while let Some(m) = self.try_recv()? {
            latest = Some(m);
        }
        Ok(latest)
    }

    /// The service name.
    pub fn service(&self) -> &str {
        &self.service
    }
}

impl<T: Msg> Wakeable for Subscriber<T> {
    fn service_name(&self) -> &str {
        &self.service
    }
    fn event_factory(&self) -> &EventFactory {
        &self.event
    }
}

impl Bus {
    /// A publisher of `T` on `service` (created with raised limits if new).
    pub fn publisher<T: Msg>(&self, service: &str) -> Result<Publisher<T>, BusError> {
        let factory = self.message_service::<T>(service)?;
        let publisher = factory
            .publisher_builder()
            .create()
            .map_err(|e| BusError::port(service, e))?;
        let notifier = self
            .event_service(service)?
            .notifier_builder()
            .create()
            .map_err(|e| BusError::port(service, e))?;
        Ok(Publisher {
            service: service.to_string(),
            publisher,
            notifier,
        })
    }

    /// A subscriber of `T` on `service`; attach it to a [`crate::Waiter`] to
    /// be woken by the publishers.
    pub fn subscriber<T: Msg>(&self, service: &str) -> Result<Subscriber<T>, BusError> {
        let factory = self.message_service::<T>(service)?;
        let subscriber = factory
            .subscriber_builder()
            .create()
            .map_err(|e| BusError::port(service, e))?;
        Ok(Subscriber {
            service: service.to_string(),
            subscriber,
            event: self.event_service(service)?,
        })
    }
}
