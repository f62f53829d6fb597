//! The ground -> suite command route as the node sees it: the runtime's
//! link forwards postcard `Command`s from `spacepose/{prefix}/wire/command`
//! to the bus; this turns its figures into health counters.

use spacepose_runtime::{Counters, LinkStatus};

/// How much of the command route's figures the node has reported.
#[derive(Debug)]
pub struct CommandRoute {
    /// The zenoh key commands arrive on (for the log).
    key: String,
    rejected_seen: u64,
    announced: bool,
    stopped_seen: bool,
}

impl CommandRoute {
    /// A route on the zenoh key `key`, nothing reported yet.
    pub fn new(key: String) -> Self {
        CommandRoute {
            key,
            rejected_seen: 0,
            announced: false,
            stopped_seen: false,
        }
    }

    /// Adds the payloads the route refused since the last call to
    /// `counters.rejected_wire` (one warning per batch; the route itself
    /// logs each one), and counts a stopped route once as an error.
    pub fn report(&mut self, link: &LinkStatus, counters: &mut Counters) {
        let total = link.stats.rejected_wire;
        let new = total.saturating_sub(self.rejected_seen);
        if new > 0 {
            self.rejected_seen = total;
            counters.rejected_wire += new;
            tracing::warn!(
                new,
                total,
                "zenoh command payloads rejected (garbage, wrong schema version or kind)"
            );
        }
        if link.running && !self.announced {
            self.announced = true;
            tracing::info!(key = self.key, "accepting commands from zenoh");
        }
        if !link.running && !self.stopped_seen {
            self.stopped_seen = true;
            counters.errors += 1;
            tracing::error!("the command bridge stopped: zenoh commands are no longer forwarded");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn status(rejected: u64, running: bool) -> LinkStatus {
        let mut s = LinkStatus {
            running,
            ..LinkStatus::default()
        };
        s.stats.rejected_wire = rejected;
        s
    }

    #[test]
    fn rejections_are_added_as_deltas_and_a_stop_counts_once() {
        let mut route = CommandRoute::new("spacepose/t/wire/command".into());
        let mut c = Counters {
            rejected_wire: 2, // refused bus messages, counted by the node
            ..Counters::default()
        };
        route.report(&status(0, true), &mut c);
        assert_eq!((c.rejected_wire, c.errors), (2, 0));
        route.report(&status(3, true), &mut c);
        route.report(&status(3, true), &mut c);
        assert_eq!(c.rejected_wire, 5);
        route.report(&status(7, false), &mut c);
        route.report(&status(7, false), &mut c);
        assert_eq!((c.rejected_wire, c.errors), (9, 1));
    }
}
