//! Service limits set when a service is created (raised above the iceoryx2
//! defaults of 2 publishers, 8 subscribers and 20 nodes, for redundancy).
//!
//! Every process opens services through [`crate::Bus`], so creator and
//! openers always agree on these values (iceoryx2 refuses to open a service
//! whose limits are below what the opener asks for).

/// Publishers per fixed-size message service. Every service of a
/// deployment publishes on the one health topic, and redundant instances
/// publish poses side by side, so this is well above the number of
/// processes a descriptor starts.
pub const MAX_PUBLISHERS: usize = 16;
/// Subscribers per fixed-size message service.
pub const MAX_SUBSCRIBERS: usize = 16;
/// Nodes per service.
pub const MAX_NODES: usize = 32;
/// Samples buffered per subscriber of a fixed-size message service (the
/// oldest is overwritten when full).
pub const MESSAGE_BUFFER: usize = 16;

/// Publishers per cloud service.
pub const CLOUD_MAX_PUBLISHERS: usize = 4;
/// Subscribers per cloud service. Lower than for messages because every
/// subscriber slot reserves `CLOUD_BUFFER + CLOUD_BORROWED` full-size slices in
/// the publisher's (zeroed) data segment: 8 × 3 + 1 = 25 slices of
/// `max_points × 24` bytes (120 MB at 200k points).
pub const CLOUD_MAX_SUBSCRIBERS: usize = 8;
/// Frames buffered per cloud subscriber (the oldest is overwritten when full).
pub const CLOUD_BUFFER: usize = 2;
/// Frames a cloud subscriber may hold at once.
pub const CLOUD_BORROWED: usize = 1;

/// Notifiers per event (wake-up) service.
pub const MAX_NOTIFIERS: usize = 16;
/// Listeners per event service (one per attached waiter).
pub const MAX_LISTENERS: usize = 32;
/// Nodes per event service.
pub const EVENT_MAX_NODES: usize = 36;
