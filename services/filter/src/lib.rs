//! Relative-motion filter: linear Kalman filter on position, invariant EKF on attitude, motion compensation
#![forbid(unsafe_code)]
