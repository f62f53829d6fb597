//! Point-cloud registration for spacepose: the smoothed NDT of seed 000
//! §3.1 (map: [`NdtMap`], registration: [`register_ndt`]), its
//! continuous-time variant of §3.3 ([`register_ct_ndt`]), and point-to-point
//! ICP ([`register_icp`]) with the `f_CONV` figure of seed 002 §4.5.
//!
//! Every registration returns a [`Registration`] (pose, convergence flag,
//! iterations, cost, inliers, information matrix), never just a pose. The
//! estimated pose is `t_target_sensor` (sensor frame → target body frame,
//! `T` of Eq. 3); the information matrix is in the left-perturbation
//! convention `δ = [rot; trans]` of Eq. (5).
//!
//! Everything runs on the calling thread; maps and models are built once
//! and shared read-only.
#![forbid(unsafe_code)]

pub mod ct_ndt;
pub mod degeneracy;
pub mod error;
mod gauss_newton;
pub mod icp;
mod kdtree;
pub mod ndt;
pub mod ndt_map;
mod normal_equations;
pub mod params;
pub mod result;
mod source;
pub mod synthetic;
mod voxel_box;
pub mod weak_directions;

#[cfg(test)]
mod test_support;

pub use ct_ndt::{
    CtPriors, CtRegistration, DisplacementPrior, RatePrior, ScanTimes, StartPrior,
    ct_point_jacobian, interpolate, register_ct_ndt, register_ct_ndt_free_start,
    register_ct_ndt_with_priors,
};
pub use degeneracy::hold_weak_directions;
pub use error::RegistrationError;
pub use icp::{IcpFarLookupStats, IcpLookupStats, IcpModel, register_icp};
pub use ndt::register_ndt;
pub use ndt_map::{NdtCell, NdtMap, NdtMapStats};
pub use params::{CellLookup, IcpParams, NdtMapParams, NdtParams};
pub use result::{Cost, Increment, Registration};
