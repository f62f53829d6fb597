//! The `spacepose-recorder` service: a run recorded to MCAP, and streamed
//! live to Foxglove.
//!
//! [`RecorderNode`] reads every topic of the suite that a run is made of
//! (raw and cropped clouds, pose estimates, filter states, acquisitions,
//! heartbeats and, from simulated sources, truth), all optional, and hands
//! each to a [`spacepose_foxglove::Recorder`], which writes it with
//! Foxglove's well-known schemas at the sensor time of its frame. At start
//! it records the deployment descriptor and every service's configuration
//! (attachment and metadata) and the target model; on SIGTERM it closes the
//! file so that it holds its summary and index. With a `[live]` table it
//! also hands everything to a [`spacepose_foxglove::LiveView`], a Foxglove
//! WebSocket server on loopback (clouds decimated for the link, the
//! trajectory); without a file it is a live view only.
#![forbid(unsafe_code)]

pub mod config;
pub mod live_config;
pub mod node;
pub mod run_info;

pub use config::RecorderConfig;
pub use live_config::LiveConfig;
pub use node::RecorderNode;
