//! Continuous-time smoothed NDT, seed 000 §3.3: the end pose `T^e` of a scan
//! is optimised with the start pose `T^s` fixed, each point being mapped by
//! the pose interpolated at its timestamp (Eq. 13-14), with the Jacobian of
//! Eq. (15) (Appendix A.2).

mod displacement_prior;
mod fixed_start;
mod free_start;
mod interpolation;
mod joint;
mod rate_prior;
mod start_prior;
pub use displacement_prior::DisplacementPrior;
pub use fixed_start::register_ct_ndt;
pub use free_start::{
    CtPriors, CtRegistration, register_ct_ndt_free_start, register_ct_ndt_with_priors,
};
pub use interpolation::{ScanTimes, ct_point_jacobian, interpolate};
pub use rate_prior::RatePrior;
pub use start_prior::StartPrior;

#[cfg(test)]
mod tests;
