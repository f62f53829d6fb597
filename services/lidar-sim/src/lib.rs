//! High-fidelity lidar simulator: rosette and raster scans, detection, noise, beam divergence, reflections, motion blur, clutter
#![forbid(unsafe_code)]
