//! The bus of a generated spacecraft: a box or a right prism over a
//! regular polygon (24 sides stand for a cylinder), its axis along body x.

use super::parts::{MLI, cuboid, frustum, radial};
use crate::error::TargetError;
use crate::mesh::Mesh;
use nalgebra::{Rotation3, Vector3};
use std::f64::consts::PI;

/// The cross-section of a bus.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Section {
    /// A rectangle of half widths along y and z (m).
    Rectangle {
        /// Half width along y (m).
        half_y_m: f64,
        /// Half width along z (m).
        half_z_m: f64,
    },
    /// A regular polygon of `sides` sides and circumradius `radius_m`, a
    /// vertex at `phase_rad` from +y toward +z.
    Polygon {
        /// Number of sides (24: a cylinder).
        sides: u32,
        /// Circumradius (m).
        radius_m: f64,
        /// Angle of the first vertex (rad).
        phase_rad: f64,
    },
}

/// A bus: its section, extruded over `[-half_length_m, half_length_m]`
/// along x, covered in MLI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bus {
    /// Cross-section.
    pub section: Section,
    /// Half length along x (m).
    pub half_length_m: f64,
}

impl Bus {
    /// The bus's faces (MLI).
    pub fn mesh(&self) -> Result<Mesh, TargetError> {
        let l = self.half_length_m;
        match self.section {
            Section::Rectangle { half_y_m, half_z_m } => cuboid(
                Vector3::zeros(),
                Vector3::new(2.0 * l, 2.0 * half_y_m, 2.0 * half_z_m),
                Rotation3::identity(),
                MLI,
            ),
            Section::Polygon {
                sides,
                radius_m,
                phase_rad,
            } => frustum(
                Vector3::new(-l, 0.0, 0.0),
                &Vector3::x(),
                2.0 * l,
                [radius_m, radius_m],
                sides,
                phase_rad,
                MLI,
            ),
        }
    }

    /// Distance from the x axis to the side surface along `radial(phi)` (m).
    pub fn surface_radius(&self, phi: f64) -> f64 {
        match self.section {
            Section::Rectangle { half_y_m, half_z_m } => {
                let d = radial(phi);
                let along_y = if d.y.abs() > 1e-12 {
                    half_y_m / d.y.abs()
                } else {
                    f64::INFINITY
                };
                let along_z = if d.z.abs() > 1e-12 {
                    half_z_m / d.z.abs()
                } else {
                    f64::INFINITY
                };
                along_y.min(along_z)
            }
            Section::Polygon {
                sides,
                radius_m,
                phase_rad,
            } => {
                let sector = 2.0 * PI / f64::from(sides);
                let apothem = radius_m * (PI / f64::from(sides)).cos();
                // Angle from the normal of the face that `phi` crosses.
                let mut off = (phi - phase_rad - 0.5 * sector).rem_euclid(sector);
                if off > 0.5 * sector {
                    off -= sector;
                }
                apothem / off.cos()
            }
        }
    }

    /// The largest distance from the x axis to the surface (m).
    pub fn outer_radius_m(&self) -> f64 {
        match self.section {
            Section::Rectangle { half_y_m, half_z_m } => half_y_m.hypot(half_z_m),
            Section::Polygon { radius_m, .. } => radius_m,
        }
    }

    /// The smallest distance from the x axis to the surface (m).
    pub fn inner_radius_m(&self) -> f64 {
        match self.section {
            Section::Rectangle { half_y_m, half_z_m } => half_y_m.min(half_z_m),
            Section::Polygon {
                sides, radius_m, ..
            } => radius_m * (PI / f64::from(sides)).cos(),
        }
    }

    /// Words for the description.
    pub fn describe(&self) -> String {
        let length = 2.0 * self.half_length_m;
        match self.section {
            Section::Rectangle { half_y_m, half_z_m } => format!(
                "box bus {length:.2} x {:.2} x {:.2} m",
                2.0 * half_y_m,
                2.0 * half_z_m
            ),
            Section::Polygon {
                sides, radius_m, ..
            } => {
                let kind = if sides >= 24 {
                    "cylindrical".to_owned()
                } else {
                    format!("{sides}-sided prism")
                };
                format!(
                    "{kind} bus {length:.2} m long, {:.2} m across",
                    2.0 * radius_m
                )
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit_radius(bus: &Bus, phi: f64) -> f64 {
        let mesh = bus.mesh().expect("bus mesh");
        let d = radial(phi);
        let origin = Vector3::new(0.1, 0.0, 0.0) + d * 20.0;
        let hit = mesh.cast_ray(&origin, &-d, 40.0).expect("hit");
        20.0 - hit.distance
    }

    #[test]
    fn the_surface_radius_is_where_a_ray_meets_the_side() {
        let buses = [
            Section::Rectangle {
                half_y_m: 0.8,
                half_z_m: 0.5,
            },
            Section::Polygon {
                sides: 6,
                radius_m: 1.0,
                phase_rad: 0.3,
            },
            Section::Polygon {
                sides: 5,
                radius_m: 0.7,
                phase_rad: 0.0,
            },
        ];
        for section in buses {
            let bus = Bus {
                section,
                half_length_m: 1.0,
            };
            for phi in [0.0, 0.4, 1.3, 2.9, 4.4, 5.9] {
                let (r, hit) = (bus.surface_radius(phi), hit_radius(&bus, phi));
                assert!((r - hit).abs() < 1e-9, "{section:?} at {phi}: {r} vs {hit}");
                assert!(r <= bus.outer_radius_m() + 1e-12 && r >= bus.inner_radius_m() - 1e-12);
            }
        }
    }
}
