//! The `spacepose-init` service (issue 5): acquires the pose at start and
//! whenever the tracker reports `lost`, publishes an `AcquisitionResult`
//! (pose, method, f_CONV, success, time) from which the tracker and the
//! filter restart, and retries on a later frame after a rejected result
//! (seed 002 §4.5).
//!
//! - [`node::InitNode`]: the service without any bus: holds the newest
//!   cloud, feeds the tracker's estimates to the state machine, and runs
//!   acquisitions on its [`worker::Worker`] thread.
//! - [`state::InitStateMachine`]: when to acquire (no bus, no clock).
//! - [`chain::MethodChain`]: the configured methods tried in order on one
//!   frame ([`method::PoseAcquirer`]); the result names the method that
//!   succeeded: the CNN ([`cnn_method::CnnMethod`], issue 6) first, with
//!   template matching ([`template::TemplateMatching`]) as the fallback.
//! - [`config::InitServiceConfig`]: the TOML file, and the chain it builds.
//! - [`verify::Verifier`]: while the suite tracks, acquisitions on later
//!   frames against the tracker's poses; contradictions that agree with
//!   each other replace the track.
//! - [`wire`]: estimates in, results out.
#![forbid(unsafe_code)]

pub mod chain;
pub mod cnn_method;
pub mod config;
pub mod error;
pub mod method;
pub mod node;
pub mod state;
pub mod template;
pub mod verify;
pub mod wire;
pub mod worker;

pub use chain::{Acquisition, MethodChain};
pub use cnn_method::{CnnEngine, CnnMethod, CnnMethodConfig};
pub use config::{InitServiceConfig, MethodKind};
pub use error::InitError;
pub use method::{Attempt, MethodOutput, PoseAcquirer};
pub use node::InitNode;
pub use state::{EstimateInfo, Event, InitConfig, InitStateMachine, InitStats, Phase};
pub use template::TemplateMatching;
pub use verify::{Verdict, Verifier, VerifyConfig};
