//! High-fidelity lidar simulator for spacepose: rosette (Livox Mid-40) and
//! raster scans, detection probability from SNR, range / line-of-sight noise
//! and outliers (seed 002 §3.2), beam divergence, Phong reflections and
//! motion blur (seed 004 §IV.A), and an optional test-facility background
//! (seed 000 §4.1). A library only: no bus, no I/O.
//!
#![forbid(unsafe_code)]

pub mod detection;
pub mod error;
pub mod optics;
pub mod pattern;
