//! Point-to-point ICP (Besl & McKay; seed 000 §2.1, Table 1 ICP row) against
//! the model cloud, with its nearest-point structures built once
//! ([`IcpModel`]): an exact voxel lookup grid within the correspondence
//! distance, and a kiddo kd-tree beyond it.
//!
//! Each iteration pairs every transformed point with its nearest model
//! point within `max_distance_m` and applies the closed-form optimal rigid
//! update for those pairs (Kabsch / Umeyama SVD, no scale); it stops when
//! the norm of the increment `[Log ΔR; Δp]` (left ⊕ of Eq. 5) drops below
//! `termination_increment`.

mod far_grid;
mod model;
mod nearest_memo;
mod point_grid;
mod register;
pub use model::{
    DEFAULT_GRID_MAX_DISTANCE_M, DEFAULT_GRID_RESOLUTION_M, IcpFarLookupStats, IcpLookupStats,
    IcpModel, MAX_GRID_VOXELS,
};
pub use register::register_icp;

#[cfg(test)]
mod tests;
