//! [`LiveView`]: the recorder's channels, live, on a Foxglove WebSocket
//! server, with clouds decimated for the link and the trajectory.
//!
//! The server is the SDK's (`foxglove::WebSocketServer`, subprotocols
//! `foxglove.sdk.v1` and `foxglove.sdk.v1.1`, the Foxglove WebSocket
//! protocol under the SDK's names), in the view's own SDK context: it sees
//! only the view's channels, and a recorder in the same process does not
//! share them. Only channels that a client subscribes to are encoded and
//! sent. The protocol has no authentication: where it may listen is the
//! caller's decision (`docs/security.md`).

use crate::cloud::{point_cloud_every, point_step};
use crate::error::RecordError;
use crate::log::{Logger, keeps_cloud};
use crate::pose::{SensorPose, poses_in_frame};
use crate::scene::TargetMesh;
use crate::stamp::log_time_ns;
use crate::topics;
use foxglove::messages::PosesInFrame;
use foxglove::websocket::{Capability, ChannelView, Client, ServerListener};
use foxglove::{Channel, Context, PartialMetadata, WebSocketServer, WebSocketServerHandle};
use spacepose_messages::{Cloud, Message};
use std::collections::VecDeque;
use std::net::{IpAddr, SocketAddr};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// What the live view sends, decimated for the link.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LiveOptions {
    /// Send the raw cloud of every n-th frame (by sequence); 0: none.
    pub raw_cloud_every: u64,
    /// Send the cropped cloud of every n-th frame (by sequence); 0: none.
    pub cloud_every: u64,
    /// At most this many points per cloud (every k-th point kept); 0: all.
    pub max_points: usize,
    /// Estimates in the trajectory (`/spacepose/pose/trajectory`); 0: none.
    pub trajectory: usize,
}

impl Default for LiveOptions {
    fn default() -> Self {
        Self {
            raw_cloud_every: 0,
            cloud_every: 1,
            max_points: 2_000,
            trajectory: 100,
        }
    }
}

/// What the live view has sent so far.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LiveStats {
    /// Clouds logged.
    pub clouds: u64,
    /// Clouds skipped by the frame decimation.
    pub clouds_skipped: u64,
    /// Points in the clouds logged.
    pub points: u64,
    /// Fixed-size messages logged.
    pub messages: u64,
}

/// Asks for the scene again when a client subscribes to it: the model is
/// sent once per subscriber, not per frame.
struct SceneOnSubscribe(Arc<AtomicBool>);

impl ServerListener for SceneOnSubscribe {
    fn on_subscribe(&self, _client: Client, channel: ChannelView) {
        if channel.topic() == topics::SCENE {
            self.0.store(true, Ordering::Relaxed);
        }
    }
}

/// A Foxglove WebSocket server streaming the suite's channels live. The
/// server stops with [`LiveView::stop`] or when the view is dropped.
pub struct LiveView {
    log: Logger,
    options: LiveOptions,
    server: Option<WebSocketServerHandle>,
    addr: SocketAddr,
    trajectory: VecDeque<SensorPose>,
    trajectory_ch: Channel<PosesInFrame>,
    scene_wanted: Arc<AtomicBool>,
    /// Sensor time last published to the clients (ns).
    time_sent_ns: u64,
    stats: LiveStats,
    /// Keeps the channels' context alive for the server's lifetime.
    _context: Arc<Context>,
}

impl LiveView {
    /// Starts the server on `addr` (port 0: any free port, see
    /// [`LiveView::local_addr`]).
    ///
    /// # Errors
    /// The address cannot be bound; a channel cannot be declared.
    pub fn start(addr: SocketAddr, options: LiveOptions) -> Result<Self, RecordError> {
        let context = Context::new();
        let log = Logger::new(&context)?;
        let trajectory_ch = context.channel_builder(topics::TRAJECTORY).build();
        let scene_wanted = Arc::new(AtomicBool::new(false));
        let host = match addr.ip() {
            IpAddr::V4(ip) => ip.to_string(),
            IpAddr::V6(ip) => format!("[{ip}]"),
        };
        let server = WebSocketServer::new()
            .name("spacepose")
            .bind(host, addr.port())
            .context(&context)
            .capabilities([Capability::Time])
            .listener(Arc::new(SceneOnSubscribe(Arc::clone(&scene_wanted))))
            .start_blocking()
            .map_err(|source| RecordError::Server {
                addr: addr.to_string(),
                source,
            })?;
        let addr = SocketAddr::new(addr.ip(), server.port());
        Ok(Self {
            log,
            options,
            server: Some(server),
            addr,
            trajectory: VecDeque::new(),
            trajectory_ch,
            scene_wanted,
            time_sent_ns: 0,
            stats: LiveStats::default(),
            _context: context,
        })
    }

    /// The address the server listens on.
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// Clients connected now.
    pub fn clients(&self) -> usize {
        self.server
            .as_ref()
            .map_or(0, WebSocketServerHandle::client_count)
    }

    /// What was sent so far.
    pub fn stats(&self) -> LiveStats {
        self.stats
    }

    /// The target model, shown at the estimated and the true pose; sent
    /// with the next message, and again whenever a client subscribes to it.
    pub fn set_target(&mut self, mesh: TargetMesh) {
        self.log.set_target(mesh);
    }

    /// Sends the scene again when a client asked for it.
    fn before_log(&mut self) {
        if self.scene_wanted.swap(false, Ordering::Relaxed) {
            self.log.resend_scene();
        }
    }

    /// Publishes the sensor time when it advanced (the protocol's `time`
    /// goes through each client's control queue: once per frame, not per
    /// message).
    fn after_log(&mut self) {
        let now = self.log.newest_ns();
        if now > self.time_sent_ns
            && let Some(server) = &self.server
        {
            server.broadcast_time(now);
            self.time_sent_ns = now;
        }
    }

    /// Sends a cloud (raw or cropped) decimated to the point budget, unless
    /// the frame decimation skips it. Returns whether it was sent.
    ///
    /// # Errors
    /// The header could not be written as JSON.
    pub fn cloud(&mut self, cloud: Cloud<'_>) -> Result<bool, RecordError> {
        if !keeps_cloud(
            &cloud,
            self.options.raw_cloud_every,
            self.options.cloud_every,
        ) {
            self.stats.clouds_skipped += 1;
            return Ok(false);
        }
        self.before_log();
        let step = point_step(cloud.points.len(), self.options.max_points);
        let message = point_cloud_every(cloud.points, step, cloud.header.scan_end_s);
        let kept = cloud.points.len().div_ceil(step);
        self.log.cloud(&cloud, &message, kept)?;
        self.after_log();
        self.stats.clouds += 1;
        self.stats.points += kept as u64;
        Ok(true)
    }

    /// Sends a fixed-size message on its channels (commands are not sent);
    /// an estimate also extends the trajectory.
    ///
    /// # Errors
    /// A message with unknown codes or a degenerate rotation.
    pub fn message(&mut self, msg: &Message) -> Result<(), RecordError> {
        self.before_log();
        if !self.log.message(msg)? {
            return Ok(());
        }
        if let Message::Pose(m) = msg
            && self.options.trajectory > 0
        {
            if self.trajectory.len() == self.options.trajectory {
                self.trajectory.pop_front();
            }
            self.trajectory.push_back(SensorPose::from(m));
            let meta = PartialMetadata::with_log_time(log_time_ns(m.t_s));
            self.trajectory_ch
                .log_with_meta(&poses_in_frame(&self.trajectory), meta);
        }
        self.after_log();
        self.stats.messages += 1;
        Ok(())
    }

    /// Stops the server: clients are disconnected, the server's tasks
    /// have ended. The SDK closes the listening socket asynchronously, a
    /// moment later.
    pub fn stop(mut self) -> LiveStats {
        self.shutdown();
        self.stats
    }

    fn shutdown(&mut self) {
        if let Some(server) = self.server.take() {
            server.stop().wait_blocking();
        }
    }
}

impl Drop for LiveView {
    fn drop(&mut self) {
        self.shutdown();
    }
}

#[cfg(test)]
#[path = "live_tests.rs"]
mod tests;
