//! Tracking loop: NDT, NDT-deblurring, CT-NDT and ICP modes with loss detection
#![forbid(unsafe_code)]
