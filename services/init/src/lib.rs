//! The init service (issue 5): acquires the pose at start and whenever the
//! tracker reports `lost`, publishes an `AcquisitionResult` (pose, method,
//! f_CONV, success, time) from which the tracker and the filter restart,
//! and retries on a later frame after a rejected result (seed 002 §4.5).
//!
//! - [`state::InitStateMachine`]: when to acquire (no bus, no clock).
//! - [`chain::MethodChain`]: the configured methods tried in order on one
//!   frame ([`method::PoseAcquirer`]); the result names the method that
//!   succeeded: the CNN ([`cnn_method::CnnMethod`], issue 6) first, with
//!   template matching ([`template::TemplateMatching`]) as the fallback.
//! - `src/main.rs` moves messages between the bus and these.
#![forbid(unsafe_code)]

pub mod chain;
pub mod cnn_method;
pub mod config;
pub mod error;
pub mod method;
pub mod state;
pub mod template;

pub use chain::{Acquisition, MethodChain};
pub use cnn_method::{CnnEngine, CnnMethod, CnnMethodConfig};
pub use config::{InitServiceConfig, MethodKind};
pub use error::InitError;
pub use method::{Attempt, MethodOutput, PoseAcquirer};
pub use state::{EstimateInfo, Event, InitConfig, InitStateMachine, InitStats, Phase};
pub use template::TemplateMatching;

use spacepose_target::Target;
use std::sync::Arc;

impl InitServiceConfig {
    /// Resolves the target and builds every configured method, in order.
    pub fn build_chain(&self) -> Result<MethodChain, InitError> {
        let target = Target::resolve(&self.target, self.target_scale)
            .map_err(|e| InitError::InvalidConfig(format!("target {:?}: {e}", self.target)))?;
        let target = Arc::new(target);
        let mut methods: Vec<Box<dyn PoseAcquirer>> = Vec::new();
        for kind in &self.methods {
            match kind {
                MethodKind::TemplateMatching => methods.push(Box::new(TemplateMatching::new(
                    target.clone(),
                    self.sensor(),
                    self.template_matching.clone(),
                )?)),
                MethodKind::Cnn => {
                    methods.push(Box::new(CnnMethod::new(target.clone(), &self.cnn)?));
                }
            }
        }
        MethodChain::new(methods, self.min_points)
    }
}
