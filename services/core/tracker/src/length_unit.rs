//! The tracker's lengths in units of the target's NDT length ℓ.
//!
//! Seed 000 Table 1 gives one NDT cell size, 7.5 cm, for a target of a few
//! metres; every length of the tracking loop that is about the map (cell,
//! smoothing, association distance, voxel leaf, model spacing, lever-arm
//! holds, position limits) was set against it. A 20 m target seen with the
//! same 7.5 cm cells has a basin of 7.5 cm at 10 m from its centre of mass,
//! 0.4° of attitude, so a tumble's first frames are never recovered. The
//! target package therefore records a length unit ℓ
//! (`Calibration::length_unit_m`: max(7.5 cm, 0.018 √A), A the surface
//! area, so that the map keeps about as many cells across the target as on
//! a deos-sized body), and the configured map lengths are *reference*
//! lengths for [`REFERENCE_LENGTH_M`], multiplied by `ℓ / 7.5 cm`: the
//! cell, smoothing and lookup lengths, the association distances, the
//! convergence step, the voxel leaf, the model spacing, and the position
//! limits of the loss checks (a centre of mass moves with the size).
//!
//! Sensor lengths do not scale: point noise, range gates, the visibility
//! gate's tolerance (`crate::visibility`), and the
//! lever-arm holds of the degeneracy handling, which compare how far a
//! rotation moves the surface against the range noise (2 cm), not against
//! the cell. Scaling them too held the roll of the 17 m telescope test
//! mesh from its third frame (lever arms 10-18 cm against a 14.5 cm hold)
//! and the track drifted 3.7° a frame; unscaled, it tracks (see
//! `docs/design/target-packages.md`). For any target up to about
//! 17 m² of surface, deos included, the factor is exactly 1.
//! `docs/design/target-packages.md` has the reasoning and the figures.

use crate::config::TrackerConfig;
use spacepose_registration::NdtMapParams;

pub use crate::model::REFERENCE_LENGTH_M;

impl TrackerConfig {
    /// This configuration with its map-related lengths multiplied by
    /// `factor` (ℓ / [`REFERENCE_LENGTH_M`]).
    pub fn scaled_lengths(&self, factor: f64) -> TrackerConfig {
        let mut c = self.clone();
        c.voxel_leaf_m *= factor;
        c.ndt.max_distance_m *= factor;
        c.ndt.termination_translation_m *= factor;
        c.icp.max_distance_m *= factor;
        c.loss.max_final_increment_m *= factor;
        c.loss.max_innovation_pos_m *= factor;
        c
    }
}

/// The NDT map parameters for a length factor (ℓ / [`REFERENCE_LENGTH_M`]):
/// the defaults with every length multiplied.
pub fn map_params_scaled(factor: f64) -> NdtMapParams {
    let d = NdtMapParams::default();
    NdtMapParams {
        min_cell_size_m: d.min_cell_size_m * factor,
        smoothing_sigma_m: d.smoothing_sigma_m * factor,
        eigen_floor_abs_m: d.eigen_floor_abs_m * factor,
        lookup_max_distance_m: d.lookup_max_distance_m * factor,
        lookup_resolution_m: d.lookup_resolution_m * factor,
        ..d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_factor_of_one_changes_nothing_and_two_doubles_the_map_lengths() {
        let c = TrackerConfig::default();
        assert_eq!(c.scaled_lengths(1.0), c);
        assert_eq!(map_params_scaled(1.0), NdtMapParams::default());
        let d = c.scaled_lengths(2.0);
        assert_eq!(d.voxel_leaf_m, 2.0 * c.voxel_leaf_m);
        assert_eq!(d.ndt.max_distance_m, 2.0 * c.ndt.max_distance_m);
        assert_eq!(d.min_lever_arm_m(), c.min_lever_arm_m(), "a sensor length");
        assert_eq!(
            d.icp.point_sigma_m, c.icp.point_sigma_m,
            "sensor noise does not scale"
        );
        assert_eq!(d.loss.max_innovation_rot_deg, c.loss.max_innovation_rot_deg);
        let m = map_params_scaled(2.0);
        assert_eq!(m.min_cell_size_m, 0.15);
        assert_eq!(
            m.lookup_max_distance_m,
            2.0 * d.ndt.max_distance_m / 2.0 * 1.0
        );
        assert_eq!(
            m.min_points_per_cell,
            NdtMapParams::default().min_points_per_cell
        );
    }
}
