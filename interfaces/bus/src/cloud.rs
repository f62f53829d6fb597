//! Clouds as iceoryx2 slices: `[WirePoint]` payload with a `CloudHeader`
//! user header, Static allocation sized to the largest frame.

use crate::error::BusError;
use crate::node::Bus;
use crate::waiter::{EventFactory, Wakeable};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher as IoxPublisher;
use iceoryx2::port::subscriber::Subscriber as IoxSubscriber;
use iceoryx2::prelude::*;
use iceoryx2::sample::Sample;
use spacepose_geometry::Point;
use spacepose_messages::{
    CloudHeader, CloudMsg, SCHEMA_VERSION, WirePoint, as_points, as_wire, realtime_ns,
};
use std::fmt::Debug;

/// Publisher of clouds with a fixed capacity (points per frame).
pub struct CloudPublisher {
    service: String,
    publisher: IoxPublisher<ipc::Service, [WirePoint], CloudHeader>,
    notifier: Notifier<ipc::Service>,
    capacity: usize,
}

impl Debug for CloudPublisher {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CloudPublisher")
            .field("service", &self.service)
            .field("capacity", &self.capacity)
            .finish()
    }
}

impl CloudPublisher {
    /// Sends a frame: copies `points` into shared memory, sets the header's
    /// `schema`, `point_count` and `published_ns` (now), sends and notifies.
    /// A frame larger than [`CloudPublisher::capacity`] is not sent:
    /// [`BusError::CloudTooLarge`].
    pub fn send(&self, header: CloudHeader, points: &[Point]) -> Result<(), BusError> {
        let wire = as_wire(points);
        self.send_with(header, points.len(), |sample| sample.write_from_slice(wire))
    }

    /// Sends a frame of `count` points produced by `point(i)` directly into
    /// shared memory (no intermediate buffer). Same checks as [`CloudPublisher::send`].
    pub fn send_from_fn(
        &self,
        header: CloudHeader,
        count: usize,
        mut point: impl FnMut(usize) -> Point,
    ) -> Result<(), BusError> {
        self.send_with(header, count, |sample| {
            sample.write_from_fn(|i| WirePoint::from(point(i)))
        })
    }

    fn send_with(
        &self,
        mut header: CloudHeader,
        count: usize,
        write: impl FnOnce(
            iceoryx2::sample_mut_uninit::SampleMutUninit<
                ipc::Service,
                [std::mem::MaybeUninit<WirePoint>],
                CloudHeader,
            >,
        )
            -> iceoryx2::sample_mut::SampleMut<ipc::Service, [WirePoint], CloudHeader>,
    ) -> Result<(), BusError> {
        let point_count = u32::try_from(count).ok().filter(|_| count <= self.capacity);
        let Some(point_count) = point_count else {
            return Err(BusError::CloudTooLarge {
                service: self.service.clone(),
                points: count,
                capacity: self.capacity,
            });
        };
        let uninit = self
            .publisher
            .loan_slice_uninit(count)
            .map_err(|e| BusError::send(&self.service, e))?;
        let mut sample = write(uninit);
        header.schema = SCHEMA_VERSION;
        header.point_count = point_count;
        header.published_ns = realtime_ns();
        *sample.user_header_mut() = header;
        sample
            .send()
            .map_err(|e| BusError::send(&self.service, e))?;
        self.notifier
            .notify()
            .map_err(|e| BusError::send(&self.service, e))?;
        Ok(())
    }

    /// Largest frame (points) this publisher can send.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// The service name.
    pub fn service(&self) -> &str {
        &self.service
    }
}

/// A received frame, borrowed from shared memory (zero copy). Dropping it
/// returns the slice to the publisher.
pub struct CloudSample {
    sample: Sample<ipc::Service, [WirePoint], CloudHeader>,
}

impl Debug for CloudSample {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CloudSample")
            .field("header", self.header())
            .field("points", &self.len())
            .finish()
    }
}

impl CloudSample {
    /// The frame header.
    pub fn header(&self) -> &CloudHeader {
        self.sample.user_header()
    }

    /// The points, as geometry points (zero copy).
    pub fn points(&self) -> &[Point] {
        as_points(self.sample.payload())
    }

    /// The points as received.
    pub fn wire(&self) -> &[WirePoint] {
        self.sample.payload()
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.sample.payload().len()
    }

    /// True for an empty frame.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// An owned copy (for zenoh or for keeping beyond the sample).
    pub fn to_msg(&self) -> CloudMsg {
        CloudMsg::new(*self.header(), self.points().to_vec())
    }
}

/// Subscriber of clouds.
pub struct CloudSubscriber {
    service: String,
    subscriber: IoxSubscriber<ipc::Service, [WirePoint], CloudHeader>,
    event: EventFactory,
}

impl Debug for CloudSubscriber {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CloudSubscriber")
            .field("service", &self.service)
            .finish()
    }
}

impl CloudSubscriber {
    /// The next buffered frame, if any (never blocks).
    pub fn try_recv(&self) -> Result<Option<CloudSample>, BusError> {
        let sample = self
            .subscriber
            .receive()
            .map_err(|e| BusError::receive(&self.service, e))?;
        Ok(sample.map(|sample| CloudSample { sample }))
    }

    /// Drains the buffer and returns the newest frame, if any (older frames
    /// are dropped: use it when only the latest scan matters).
    pub fn try_recv_latest(&self) -> Result<Option<CloudSample>, BusError> {
        let mut latest = None;
        while let Some(s) = self.try_recv()? {
            latest = Some(s);
        }
        Ok(latest)
    }

    /// The service name.
    pub fn service(&self) -> &str {
        &self.service
    }
}

impl Wakeable for CloudSubscriber {
    fn service_name(&self) -> &str {
        &self.service
    }
    fn event_factory(&self) -> &EventFactory {
        &self.event
    }
}

impl Bus {
    /// A cloud publisher on `service` whose shared memory holds frames of up
    /// to `max_points` (Static allocation: the segment never grows, so a
    /// subscriber never misses a slice because the publisher remapped).
    pub fn cloud_publisher(
        &self,
        service: &str,
        max_points: usize,
    ) -> Result<CloudPublisher, BusError> {
        let publisher = self
            .cloud_service(service)?
            .publisher_builder()
            .initial_max_slice_len(max_points.max(1))
            .allocation_strategy(AllocationStrategy::Static)
            .max_loaned_samples(1)
            .create()
            .map_err(|e| BusError::port(service, e))?;
        let notifier = self
            .event_service(service)?
            .notifier_builder()
            .create()
            .map_err(|e| BusError::port(service, e))?;
        Ok(CloudPublisher {
            service: service.to_string(),
            publisher,
            notifier,
            capacity: max_points,
        })
    }

    /// A cloud subscriber on `service`.
    pub fn cloud_subscriber(&self, service: &str) -> Result<CloudSubscriber, BusError> {
        let subscriber = self
            .cloud_service(service)?
            .subscriber_builder()
            .create()
            .map_err(|e| BusError::port(service, e))?;
        Ok(CloudSubscriber {
            service: service.to_string(),
            subscriber,
            event: self.event_service(service)?,
        })
    }
}
