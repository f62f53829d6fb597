//! The in-memory transport: several nodes wired by the topic graph in one
//! thread, every message delivered in the order it was sent.
//!
//! Node unit tests use it instead of processes; `spacepose eval` runs the
//! suite's own ingest, tracker and filter nodes on it, so the evaluation
//! scores the deployed frame path with no bus in between.

use crate::node::{Ctx, Flow, Node, Outbox};
use spacepose_geometry::Point;
use spacepose_messages::{Cloud, CloudHeader, Counters, Message, ServiceKind, Topic};
use std::any::Any;
use std::collections::VecDeque;

/// Something published on a [`LocalBus`]. (Messages are fixed-size and
/// `Copy`; boxing the large ones would allocate per message.)
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum Envelope {
    /// A fixed-size message.
    Message(Message),
    /// A cloud, owned.
    Cloud {
        /// Its topic.
        topic: Topic,
        /// Its header.
        header: CloudHeader,
        /// Its points.
        points: Vec<Point>,
    },
    /// JSON for the ground link (not delivered to nodes).
    Json {
        /// Telemetry key.
        key: String,
        /// The document.
        json: String,
    },
}

impl Envelope {
    /// The topic of a message or cloud; `None` for JSON.
    pub fn topic(&self) -> Option<Topic> {
        match self {
            Envelope::Message(m) => Some(m.topic()),
            Envelope::Cloud { topic, .. } => Some(*topic),
            Envelope::Json { .. } => None,
        }
    }
}

/// Collects a node's outputs, in order (what `LocalBus` routes; node unit
/// tests drive a node over one with `Ctx::new`).
#[derive(Debug, Default)]
pub struct Collect(pub Vec<Envelope>);

impl Outbox for Collect {
    fn message(&mut self, msg: &Message) -> anyhow::Result<()> {
        self.0.push(Envelope::Message(*msg));
        Ok(())
    }

    fn cloud(&mut self, topic: Topic, header: CloudHeader, points: &[Point]) -> anyhow::Result<()> {
        self.0.push(Envelope::Cloud {
            topic,
            header,
            points: points.to_vec(),
        });
        Ok(())
    }

    fn json(&mut self, key: &str, json: &str) -> anyhow::Result<()> {
        self.0.push(Envelope::Json {
            key: key.to_string(),
            json: json.to_string(),
        });
        Ok(())
    }
}

/// A node behind the object-safe face the bus needs.
trait Hosted {
    fn kind(&self) -> ServiceKind;
    fn deliver(&mut self, envelope: &Envelope, ctx: &mut Ctx<'_>);
    fn poll(&mut self, ctx: &mut Ctx<'_>) -> Flow;
    fn as_any(&self) -> &dyn Any;
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

impl<N: Node + 'static> Hosted for N {
    fn kind(&self) -> ServiceKind {
        N::KIND
    }

    fn deliver(&mut self, envelope: &Envelope, ctx: &mut Ctx<'_>) {
        match envelope {
            Envelope::Message(m) => self.on_message(m, ctx),
            Envelope::Cloud {
                topic,
                header,
                points,
            } => self.on_cloud(
                Cloud {
                    topic: *topic,
                    header,
                    points,
                },
                ctx,
            ),
            Envelope::Json { .. } => {}
        }
    }

    fn poll(&mut self, ctx: &mut Ctx<'_>) -> Flow {
        Node::poll(self, ctx)
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

struct Slot {
    node: Box<dyn Hosted>,
    counters: Counters,
}

/// Nodes wired by the topic graph, in one thread.
///
/// [`LocalBus::run`] delivers each queued envelope to every node whose kind
/// reads its topic (in the order the nodes were added), polls that node,
/// and queues what it sent, until nothing is left. The clock is
/// [`LocalBus::now_ns`], set by the caller.
#[derive(Default)]
pub struct LocalBus {
    slots: Vec<Slot>,
    queue: VecDeque<Envelope>,
    /// The clock the nodes see (ns).
    pub now_ns: i64,
}

impl LocalBus {
    /// An empty bus at time 0.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a node; returns its index.
    pub fn add<N: Node + 'static>(&mut self, node: N) -> usize {
        self.slots.push(Slot {
            node: Box::new(node),
            counters: Counters::default(),
        });
        self.slots.len() - 1
    }

    /// The node at `index`, if it is an `N`.
    pub fn node<N: Node + 'static>(&self, index: usize) -> Option<&N> {
        self.slots.get(index)?.node.as_any().downcast_ref()
    }

    /// The node at `index`, mutably, if it is an `N`.
    pub fn node_mut<N: Node + 'static>(&mut self, index: usize) -> Option<&mut N> {
        self.slots.get_mut(index)?.node.as_any_mut().downcast_mut()
    }

    /// The counters of the node at `index`.
    pub fn counters(&self, index: usize) -> Option<&Counters> {
        self.slots.get(index).map(|s| &s.counters)
    }

    /// Queues a message from outside the nodes (a source, a test).
    pub fn publish(&mut self, msg: Message) {
        self.queue.push_back(Envelope::Message(msg));
    }

    /// Queues a cloud from outside the nodes.
    pub fn publish_cloud(&mut self, topic: Topic, header: CloudHeader, points: Vec<Point>) {
        self.queue.push_back(Envelope::Cloud {
            topic,
            header,
            points,
        });
    }

    /// Delivers until nothing is left; returns what the nodes sent, in order.
    pub fn run(&mut self) -> Vec<Envelope> {
        let mut sent = Vec::new();
        while let Some(envelope) = self.queue.pop_front() {
            let Some(topic) = envelope.topic() else {
                continue;
            };
            for slot in &mut self.slots {
                if !slot.node.kind().reads(topic) {
                    continue;
                }
                let mut out = Collect::default();
                let mut ctx = Ctx::new(&mut out, &mut slot.counters, self.now_ns);
                slot.node.deliver(&envelope, &mut ctx);
                slot.node.poll(&mut ctx);
                for e in out.0 {
                    if e.topic().is_some() {
                        self.queue.push_back(e.clone());
                    }
                    sent.push(e);
                }
            }
        }
        sent
    }

    /// Polls every node once (timers) and delivers what that sends;
    /// returns everything sent, the polls' outputs first.
    pub fn poll(&mut self) -> Vec<Envelope> {
        let mut sent = Vec::new();
        for slot in &mut self.slots {
            let mut out = Collect::default();
            let mut ctx = Ctx::new(&mut out, &mut slot.counters, self.now_ns);
            slot.node.poll(&mut ctx);
            for e in out.0 {
                if e.topic().is_some() {
                    self.queue.push_back(e.clone());
                }
                sent.push(e);
            }
        }
        sent.extend(self.run());
        sent
    }
}
