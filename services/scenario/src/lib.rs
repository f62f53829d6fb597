//! Relative-motion scenarios with ground truth: slow-spin, tumbling, safety ellipse, random attitudes
#![forbid(unsafe_code)]
