//! The evaluation tools of spacepose, apart from the processes: each
//! sub-command of `spacepose` that simulates, scores or calibrates is a
//! module with its clap arguments and a `run` function, so tests call it
//! without spawning a process.
//!
//! Truth only scores: it reaches an estimator only as the documented truth
//! initialisation (`truth_init`), the same message the simulated sensor
//! publishes. `eval tracking` runs the suite's own ingest, tracker and
//! filter nodes in one process ([`tracking`]), so it scores the deployed
//! frame path.
#![forbid(unsafe_code)]

pub mod calibrate;
pub mod cnn;
pub mod common;
pub mod dataset;
pub mod plot;
pub mod seeds;
pub mod sim;
pub mod stats;
pub mod table;
pub mod tables;
pub mod target;
pub mod tm;
pub mod track;
pub mod tracking;
pub mod train;
pub mod truth_csv;
