//! The spacepose command line as a library: each sub-command is a module
//! with a `run` function, so tests can call it without spawning a process.
#![forbid(unsafe_code)]

pub mod calibrate;
pub mod cli;
pub mod common;
pub mod dataset_cmd;
pub mod eval;
pub mod ground;
pub mod sim_cmd;
pub mod suite;
pub mod truth_csv;
