//! Test-facility background (seed 000 §4.1, seed 004 §IV.C): the lidar at
//! EPOS also sees the floor, the back wall (curtains) and the robot arm that
//! holds the target mockup from below. Those returns are what the ingest
//! service has to crop. Off by default (`Effects::clutter`).
//!
//! The layout is built per frame in the sensor frame (z boresight, y down),
//! relative to the target position at scan end, from `Mesh::cuboid`:
//! - floor: horizontal slab `floor_below_target_m` below the target centre
//!   (at least the bounding radius + 0.3 m, so it never cuts the target),
//!   from the sensor to the back wall;
//! - back wall: vertical slab `wall_behind_target_m` behind the target
//!   (at least the bounding radius + 0.3 m);
//! - robot arm: a square column from the underside of the target (found by
//!   casting a ray upward to the centre of mass) down to the floor.
//!
//! Clutter surfaces are Lambertian (`k_d = 1`) with reflectance
//! `reflectance`; they send no secondary reflection.

use crate::error::{SimError, check_positive};
use nalgebra::{Rotation3, Vector3};
use spacepose_geometry::Pose;
use spacepose_model::{Mesh, Target};

/// Geometry and reflectance of the facility background.
#[derive(Debug, Clone, PartialEq)]
pub struct Facility {
    /// Height of the target centre above the floor (m).
    pub floor_below_target_m: f64,
    /// Distance from the target centre to the back wall, along the boresight (m).
    pub wall_behind_target_m: f64,
    /// Half width of the square robot-arm column (m).
    pub arm_half_width_m: f64,
    /// Half extent of the floor and wall across the boresight (m).
    pub half_width_m: f64,
    /// Reflectance ρ_T of every facility surface (Lambertian).
    pub reflectance: f64,
}

impl Default for Facility {
    /// Floor 2.5 m below the target, wall 6 m behind it, a 0.4 m wide arm,
    /// 30 m wide surfaces, reflectance 0.3 (grey paint and curtains).
    fn default() -> Self {
        Facility {
            floor_below_target_m: 2.5,
            wall_behind_target_m: 6.0,
            arm_half_width_m: 0.2,
            half_width_m: 30.0,
            reflectance: 0.3,
        }
    }
}

/// Half thickness of the floor and wall slabs (m).
const SLAB_HALF_THICKNESS_M: f64 = 0.05;

impl Facility {
    /// Rejects NaN and non-positive values (reflectance must be in (0, 1]).
    pub fn validate(&self) -> Result<(), SimError> {
        check_positive("facility.floor_below_target_m", self.floor_below_target_m)?;
        check_positive("facility.wall_behind_target_m", self.wall_behind_target_m)?;
        check_positive("facility.arm_half_width_m", self.arm_half_width_m)?;
        check_positive("facility.half_width_m", self.half_width_m)?;
        check_positive("facility.reflectance", self.reflectance)?;
        if self.reflectance > 1.0 {
            return Err(SimError::InvalidConfig {
                field: "facility.reflectance",
                value: self.reflectance,
                reason: "must be <= 1",
            });
        }
        Ok(())
    }

    /// The background meshes in the sensor frame for a target at `t_sensor_target`
    /// (finite pose required; the caller checks it).
    pub fn build(&self, target: &Target, t_sensor_target: &Pose) -> Vec<Mesh> {
        let p = t_sensor_target.translation;
        let r = target.bounding_radius();
        let floor_y = p.y + self.floor_below_target_m.max(r + 0.3);
        let wall_z = p.z + self.wall_behind_target_m.max(r + 0.3);
        let id = Rotation3::identity();
        let h = self.half_width_m;
        let floor_near = 0.0f64.min(p.z - h);
        let floor = Mesh::cuboid(
            Vector3::new(
                p.x,
                floor_y + SLAB_HALF_THICKNESS_M,
                0.5 * (floor_near + wall_z),
            ),
            Vector3::new(h, SLAB_HALF_THICKNESS_M, 0.5 * (wall_z - floor_near)),
            id,
            0,
        );
        let wall = Mesh::cuboid(
            Vector3::new(p.x, floor_y - 0.5 * h, wall_z + SLAB_HALF_THICKNESS_M),
            Vector3::new(h, 0.5 * h, SLAB_HALF_THICKNESS_M),
            id,
            0,
        );
        let arm_top = self.arm_top(target, t_sensor_target, floor_y);
        let arm = Mesh::cuboid(
            Vector3::new(p.x, 0.5 * (arm_top + floor_y), p.z),
            Vector3::new(
                self.arm_half_width_m,
                0.5 * (floor_y - arm_top),
                self.arm_half_width_m,
            ),
            id,
            0,
        );
        // One mesh, one BVH traversal per ray; `merged` cannot fail on valid
        // cuboids, but if it did the three meshes are simply kept apart.
        let parts = [floor, wall, arm];
        match Mesh::merged(&parts) {
            Ok(mesh) => vec![mesh],
            Err(_) => parts.into(),
        }
    }

    /// Sensor-frame `y` of the target's underside above the arm: a ray cast
    /// upward (toward -y) from the floor to the centre of mass. When it
    /// misses (hollow target), the arm goes up to half the bounding radius.
    fn arm_top(&self, target: &Target, t_sensor_target: &Pose, floor_y: f64) -> f64 {
        let p = t_sensor_target.translation;
        let r_t = t_sensor_target.rotation.inverse();
        let origin_s = Vector3::new(p.x, floor_y, p.z);
        let up_s = Vector3::new(0.0, -1.0, 0.0);
        let origin_b = r_t * (origin_s - p);
        let up_b = r_t * up_s;
        match target.cast_ray(&origin_b, &up_b, floor_y - p.y) {
            Some(hit) => (floor_y - hit.distance).min(floor_y - 0.01),
            None => (p.y + 0.5 * target.bounding_radius()).min(floor_y - 0.01),
        }
    }
}
