//! The `spacepose-recorder` service: a run recorded to MCAP.
//!
//! [`RecorderNode`] reads every topic of the suite that a run is made of
//! (raw and cropped clouds, pose estimates, filter states, acquisitions,
//! heartbeats and, from simulated sources, truth), all optional, and hands
//! each to a [`spacepose_foxglove::Recorder`], which writes it with
//! Foxglove's well-known schemas at the sensor time of its frame. At start
//! it records the deployment descriptor and every service's configuration
//! (attachment and metadata) and the target model; on SIGTERM it closes the
//! file so that it holds its summary and index.
#![forbid(unsafe_code)]

pub mod config;
pub mod node;
pub mod run_info;

pub use config::RecorderConfig;
pub use node::RecorderNode;
