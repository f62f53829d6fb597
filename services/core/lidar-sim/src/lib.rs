//! High-fidelity lidar simulator for spacepose: rosette (Livox Mid-40) and
//! raster scans, detection probability from SNR, range / line-of-sight noise
//! and outliers (seed 002 §3.2), beam divergence, Phong reflections and
//! motion blur (seed 004 §IV.A), and an optional test-facility background
//! (seed 000 §4.1). A library only: no bus, no I/O.
//!
//! ```no_run
//! # use std::sync::Arc;
//! # use spacepose_lidar_sim::{LidarSimulator, SensorConfig};
//! # fn demo(truth: &spacepose_scenario::TruthState) -> Result<(), Box<dyn std::error::Error>> {
//! let target = Arc::new(spacepose_model::Target::builtin("deos")?);
//! let sim = LidarSimulator::new(target, SensorConfig::livox_mid40())?;
//! let mut rng = LidarSimulator::frame_rng(42, 0);
//! let frame = sim.simulate(truth, &mut rng);
//! println!("{} points", frame.points.len());
//! # Ok(()) }
//! ```
#![forbid(unsafe_code)]

pub mod clutter;
pub mod config;
pub mod detection;
mod echoes;
pub mod error;
pub mod frame;
mod measurement;
pub mod mismatch;
pub mod optics;
pub mod pattern;
mod scene;
pub mod simulator;
pub mod source;
pub mod surface;

pub use clutter::Facility;
pub use config::{Effects, RASTER_SCAN_TIME_S, SensorConfig, SurfaceModel};
pub use detection::{DetectionModel, DetectionParams};
pub use echoes::MAX_RAYS_PER_BEAM;
pub use error::SimError;
pub use frame::{Frame, ReturnKind};
pub use mismatch::{Mismatch, ScanPath};
pub use pattern::{Scan, ScanPattern, ScanRays};
pub use simulator::LidarSimulator;
pub use source::FrameSource;
pub use surface::Surface;

#[cfg(test)]
mod simulator_tests;
