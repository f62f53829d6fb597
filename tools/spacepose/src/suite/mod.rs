//! The service suite: deployment descriptors, `up`, `status`, `down` and
//! the `demo` main job, the supervisor (restarts, hang detection, swaps). Processes are started from a validated [`plan::Plan`];
//! nothing starts when a descriptor has a problem.

pub mod binaries;
pub mod cmd;
pub mod config_check;
pub mod demo;
pub mod descriptor;
pub mod down;
pub mod health;
pub mod launch;
pub mod partition;
pub mod plan;
pub mod problems;
pub mod process;
pub mod record;
pub mod replay;
pub mod restart;
pub mod state;
pub mod status;
pub mod supervisor;
pub mod swap;
pub mod topics;
pub mod up;
