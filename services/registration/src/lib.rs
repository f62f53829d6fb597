//! Point-cloud registration: smoothed NDT, continuous-time NDT and point-to-point ICP
#![forbid(unsafe_code)]
