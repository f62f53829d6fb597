//! Evaluations against the simulator's ground truth. Truth only scores: it
//! never reaches an estimator, except the documented truth initialisation of
//! the tracker at the first frame (acquisition comes in a later issue).

pub mod cnn;
mod cnn_render;
pub mod plot;
pub mod stats;
pub mod table;
pub mod tm;
mod tm_render;
pub mod tracking;
mod tracking_plot;
mod tracking_render;
