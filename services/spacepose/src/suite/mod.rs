//! The service suite: deployment descriptors, `up`, `status`, `down` and
//! the `demo` main job. Processes are started from a validated [`plan::Plan`];
//! nothing starts when a descriptor has a problem.

pub mod binaries;
pub mod cmd;
pub mod config_check;
pub mod demo;
pub mod descriptor;
pub mod down;
pub mod health;
pub mod kind;
pub mod launch;
pub mod plan;
pub mod process;
pub mod state;
pub mod status;
pub mod up;
