//! The bus side of a node: a subscriber for every input topic of its kind
//! and a publisher for every output, opened from the topic graph, and the
//! drain that hands what arrived to the node.

use crate::node::{Ctx, Node, Outbox};
use anyhow::{Context, bail};
use spacepose_bus::{Bus, CloudPublisher, CloudSubscriber, Publisher, Subscriber, Waiter};
use spacepose_geometry::Point;
use spacepose_messages::{
    AcquisitionResult, Cloud, CloudHeader, Command, FilterState, Health, MAX_POINTS, Message,
    Names, PoseEstimate, ServiceKind, Topic, TruthMsg,
};

macro_rules! typed_ports {
    ($($variant:ident($ty:ty)),* $(,)?) => {
        /// A subscriber of one of the message topics.
        enum MsgSubscriber { $($variant(Subscriber<$ty>)),* }
        /// A publisher of one of the message topics.
        enum MsgPublisher { $($variant(Publisher<$ty>)),* }

        impl MsgSubscriber {
            fn open(bus: &Bus, topic: Topic, service: &str) -> anyhow::Result<Self> {
                Ok(match topic {
                    $(Topic::$variant => MsgSubscriber::$variant(bus.subscriber(service)?),)*
                    other => bail!("{other:?} is not a message topic"),
                })
            }
            fn try_recv(&self) -> anyhow::Result<Option<Message>> {
                Ok(match self { $(MsgSubscriber::$variant(s) => s.try_recv()?.map(Message::$variant),)* })
            }
            fn attach(&self, waiter: &mut Waiter) -> anyhow::Result<()> {
                match self { $(MsgSubscriber::$variant(s) => { waiter.attach(s)?; })* }
                Ok(())
            }
        }

        impl MsgPublisher {
            fn open(bus: &Bus, topic: Topic, service: &str) -> anyhow::Result<Self> {
                Ok(match topic {
                    $(Topic::$variant => MsgPublisher::$variant(bus.publisher(service)?),)*
                    other => bail!("{other:?} is not a message topic"),
                })
            }
            /// Sends `msg` when it is of this publisher's type.
            fn send(&self, msg: &Message) -> Option<anyhow::Result<()>> {
                match (self, msg) {
                    $((MsgPublisher::$variant(p), Message::$variant(m)) => Some(p.send(m).map_err(Into::into)),)*
                    _ => None,
                }
            }
        }
    };
}

typed_ports!(
    Pose(PoseEstimate),
    FilterState(FilterState),
    Acquisition(AcquisitionResult),
    Truth(TruthMsg),
    Health(Health),
    Command(Command),
);

enum Input {
    Messages(Topic, MsgSubscriber),
    Clouds(Topic, CloudSubscriber),
}

/// Every port of one node.
pub(crate) struct Ports {
    kind: ServiceKind,
    inputs: Vec<Input>,
    messages: Vec<MsgPublisher>,
    clouds: Vec<(Topic, CloudPublisher)>,
}

impl Ports {
    /// Opens the ports of `kind` from the graph and attaches its inputs to
    /// `waiter`. Health is published by the runtime itself.
    pub(crate) fn open(
        bus: &Bus,
        names: &Names,
        kind: ServiceKind,
        waiter: &mut Waiter,
    ) -> anyhow::Result<Ports> {
        let mut inputs = Vec::new();
        for &(topic, _) in kind.inputs() {
            let service = names.service(topic);
            let input = if topic.is_cloud() {
                let s = bus.cloud_subscriber(&service)?;
                waiter.attach(&s)?;
                Input::Clouds(topic, s)
            } else {
                let s = MsgSubscriber::open(bus, topic, &service)?;
                s.attach(waiter)?;
                Input::Messages(topic, s)
            };
            inputs.push(input);
        }
        let mut ports = Ports {
            kind,
            inputs,
            messages: Vec::new(),
            clouds: Vec::new(),
        };
        for topic in kind.outputs(true) {
            let service = names.service(topic);
            if topic == Topic::Health {
                continue;
            } else if topic.is_cloud() {
                let p = bus.cloud_publisher(&service, MAX_POINTS)?;
                ports.clouds.push((topic, p));
            } else {
                let p = MsgPublisher::open(bus, topic, &service)
                    .with_context(|| format!("opening the {} publisher", topic.as_str()))?;
                ports.messages.push(p);
            }
        }
        Ok(ports)
    }

    /// Hands every waiting message, then every waiting cloud (each after
    /// the messages that arrived before it), to `node`.
    pub(crate) fn drain<N: Node>(&self, node: &mut N, ctx: &mut Ctx<'_>) {
        self.drain_messages(node, ctx);
        for i in 0..self.inputs.len() {
            let Input::Clouds(topic, sub) = &self.inputs[i] else {
                continue;
            };
            let topic = *topic;
            loop {
                let sample = match sub.try_recv() {
                    Ok(Some(s)) => s,
                    Ok(None) => break,
                    Err(e) => {
                        ctx.counters.errors += 1;
                        tracing::warn!("receiving {}: {e}", topic.as_str());
                        break;
                    }
                };
                self.drain_messages(node, ctx);
                let cloud = Cloud {
                    topic,
                    header: sample.header(),
                    points: sample.points(),
                };
                node.on_cloud(cloud, ctx);
            }
        }
    }

    fn drain_messages<N: Node>(&self, node: &mut N, ctx: &mut Ctx<'_>) {
        for input in &self.inputs {
            let Input::Messages(topic, sub) = input else {
                continue;
            };
            loop {
                match sub.try_recv() {
                    Ok(Some(m)) => node.on_message(&m, ctx),
                    Ok(None) => break,
                    Err(e) => {
                        ctx.counters.errors += 1;
                        tracing::warn!("receiving {}: {e:#}", topic.as_str());
                        break;
                    }
                }
            }
        }
    }
}

/// The publishers of a node, and the ground link's JSON publishing when it
/// has one.
pub(crate) struct BusOutbox<'a> {
    pub(crate) ports: &'a Ports,
    pub(crate) link: Option<&'a mut crate::link::Link>,
}

impl Outbox for BusOutbox<'_> {
    fn message(&mut self, msg: &Message) -> anyhow::Result<()> {
        for p in &self.ports.messages {
            if let Some(sent) = p.send(msg) {
                return sent;
            }
        }
        bail!(
            "{} is not an output of {}",
            msg.topic().as_str(),
            self.ports.kind
        )
    }

    fn cloud(&mut self, topic: Topic, header: CloudHeader, points: &[Point]) -> anyhow::Result<()> {
        match self.ports.clouds.iter().find(|(t, _)| *t == topic) {
            Some((_, p)) => Ok(p.send(header, points)?),
            None => bail!("{} is not an output of {}", topic.as_str(), self.ports.kind),
        }
    }

    fn json(&mut self, key: &str, json: &str) -> anyhow::Result<()> {
        match self.link.as_deref_mut() {
            Some(link) => link.publish_json(key, json),
            None => bail!("{} has no ground link", self.ports.kind),
        }
    }
}
