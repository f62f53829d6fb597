//! Event-driven wake-up: a WaitSet over the listeners of attached subscribers.

use crate::error::BusError;
use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::event;
use iceoryx2::waitset::WaitSetRunResult;
use std::time::Duration;

/// Event (wake-up) service of a topic.
pub(crate) type EventFactory = event::PortFactory<ipc::Service>;

/// Something a [`crate::Waiter`] can wait on: a subscriber with its event service.
pub trait Wakeable {
    /// Name of the service (for errors and logs).
    fn service_name(&self) -> &str;
    /// The event service notified after every send on the topic.
    #[doc(hidden)]
    fn event_factory(&self) -> &EventFactory;
}

/// Why [`Waiter::wait`] returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WakeReason {
    /// At least one attached topic was published to: drain the subscribers
    /// ([`Waiter::fired`] says which attachments).
    Notified,
    /// The timeout passed without a notification.
    Timeout,
    /// A signal interrupted the wait; wait again (SIGINT/SIGTERM then show as
    /// [`WakeReason::TerminationRequested`]).
    Interrupted,
    /// SIGINT or SIGTERM was received: the loop should stop.
    TerminationRequested,
}

/// Waits on any number of subscribers without busy polling.
///
/// Each [`Waiter::attach`] opens a listener on the subscriber's event service;
/// publishers notify after every send. The listeners are attached to the
/// iceoryx2 WaitSet for the duration of each [`Waiter::wait`] (the WaitSet
/// guards borrow them), and their pending events are consumed before `wait`
/// returns, so a sample published after `wait` returns always causes the next
/// wake-up (drain the subscribers *after* `wait`).
pub struct Waiter {
    waitset: WaitSet<ipc::Service>,
    listeners: Vec<(String, Listener<ipc::Service>)>,
    fired: Vec<usize>,
}

impl std::fmt::Debug for Waiter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let names: Vec<&str> = self.listeners.iter().map(|(n, _)| n.as_str()).collect();
        f.debug_struct("Waiter").field("attached", &names).finish()
    }
}

impl Waiter {
    pub(crate) fn new(mode: SignalHandlingMode) -> Result<Waiter, BusError> {
        let waitset = WaitSetBuilder::new()
            .signal_handling_mode(mode)
            .create::<ipc::Service>()
            .map_err(|e| BusError::WaitSet(format!("creating: {e:?}")))?;
        Ok(Waiter {
            waitset,
            listeners: Vec::new(),
            fired: Vec::new(),
        })
    }

    /// Attaches a subscriber; returns its attachment index (see [`Waiter::fired`]).
    pub fn attach(&mut self, source: &impl Wakeable) -> Result<usize, BusError> {
        let listener = source
            .event_factory()
            .listener_builder()
            .create()
            .map_err(|e| BusError::port(source.service_name(), e))?;
        self.listeners
            .push((source.service_name().to_string(), listener));
        Ok(self.listeners.len() - 1)
    }

    /// Number of attached subscribers.
    pub fn len(&self) -> usize {
        self.listeners.len()
    }

    /// True when nothing is attached ([`Waiter::wait`] then just sleeps).
    pub fn is_empty(&self) -> bool {
        self.listeners.is_empty()
    }

    /// Attachment indices that were notified in the last [`Waiter::wait`].
    pub fn fired(&self) -> &[usize] {
        &self.fired
    }

    /// Blocks until a notification, the timeout, or a signal.
    pub fn wait(&mut self, timeout: Duration) -> Result<WakeReason, BusError> {
        self.fired.clear();
        if self.listeners.is_empty() {
            std::thread::sleep(timeout);
            return Ok(WakeReason::Timeout);
        }
        let mut fired = Vec::new();
        let result = {
            let guards = self
                .listeners
                .iter()
                .map(|(_, l)| self.waitset.attach_notification(l))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| BusError::WaitSet(format!("attaching: {e:?}")))?;
            self.waitset
                .wait_and_process_once_with_timeout(
                    |id| {
                        fired.extend(
                            guards
                                .iter()
                                .enumerate()
                                .filter(|(_, g)| id.has_event_from(g))
                                .map(|(i, _)| i),
                        );
                        CallbackProgression::Continue
                    },
                    timeout,
                )
                .map_err(|e| BusError::WaitSet(format!("waiting: {e:?}")))?
        };
        // Consume the events before the caller drains the subscribers.
        for &i in &fired {
            let (name, listener) = &self.listeners[i];
            listener
                .try_wait(|_| {})
                .map_err(|e| BusError::receive(name, e))?;
        }
        fired.sort_unstable();
        fired.dedup();
        self.fired = fired;
        Ok(match result {
            WaitSetRunResult::TerminationRequest => WakeReason::TerminationRequested,
            WaitSetRunResult::Interrupt => WakeReason::Interrupted,
            _ if self.fired.is_empty() => WakeReason::Timeout,
            _ => WakeReason::Notified,
        })
    }
}
