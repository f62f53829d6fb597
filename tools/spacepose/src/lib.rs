//! The spacepose command line as a library: the operator's commands (the
//! suite's supervisor: up, status, swap, down, demo; the ground tool) and
//! the dispatch of the evaluation tools (`spacepose_eval`), so tests can
//! call them without spawning a process.
#![forbid(unsafe_code)]

pub mod cli;
pub mod ground;
pub mod suite;
