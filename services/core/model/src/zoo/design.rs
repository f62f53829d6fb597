//! The random draws of a generated spacecraft: its bus, wings and
//! appendages, arranged so that the design is exactly symmetric, nearly
//! symmetric, or not symmetric at all.

use super::bus::{Bus, Section};
use super::parts::{ALUMINIUM, SOLAR, STRUCTURE, cuboid, dish, frustum, radial};
use crate::error::TargetError;
use crate::mesh::Mesh;
use nalgebra::{Matrix3, Rotation3, Vector3};
use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{PI, TAU};

/// The symmetry a design is built to have.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Intent {
    /// Every part repeats under the `fold`-fold turn about body x.
    Exact {
        /// 2, 3 or 4.
        fold: u32,
    },
    /// As `Exact`, plus one small box that breaks the symmetry.
    Near {
        /// 2, 3 or 4.
        fold: u32,
    },
    /// Parts placed with no symmetry.
    Asymmetric,
}

/// Largest span of the wings, tip to tip (m): issue 24 item 7.
pub const MAX_SPAN_M: f64 = 30.0;
/// Thickness of a solar panel (m).
const PANEL_THICKNESS_M: f64 = 0.04;
/// Gap between hinged panels (m).
const HINGE_GAP_M: f64 = 0.05;

/// Parts and words, collected as the design is drawn.
#[derive(Default)]
pub struct Parts {
    /// Meshes of the parts.
    pub meshes: Vec<Mesh>,
    /// One phrase per part group.
    pub words: Vec<String>,
}

/// A log-uniform draw in `[lo, hi]`.
fn log_uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    (rng.random_range(lo.ln()..=hi.ln())).exp()
}

/// The bus: largest dimension 1-8 m (log-uniform); a section the
/// `fold`-fold turn maps onto itself (any section when `None`).
pub fn draw_bus(rng: &mut ChaCha8Rng, fold: Option<u32>) -> Bus {
    let size = log_uniform(rng, 1.0, 8.0);
    let along_x = rng.random_bool(0.5);
    let (length, width) = if along_x {
        (size, size * rng.random_range(0.4..0.9))
    } else {
        (size * rng.random_range(0.5..0.9), size)
    };
    let radius = 0.5 * width;
    let phase_rad = rng.random_range(0.0..TAU);
    let polygon = |sides| Section::Polygon {
        sides,
        radius_m: radius,
        phase_rad,
    };
    let rectangle = |aspect: f64| Section::Rectangle {
        half_y_m: radius,
        half_z_m: radius * aspect,
    };
    let choice = rng.random_range(0..4u32);
    let aspect = rng.random_range(0.55..0.9);
    let section = match (fold, choice) {
        (Some(2), 0) | (None, 0) => rectangle(aspect),
        (Some(4), 0) => rectangle(1.0),
        (Some(3), 0 | 1) => polygon(6),
        (Some(2), 1) | (None, 1) => polygon(6),
        (Some(4), 1) => polygon(8),
        (None, 2) => polygon(5),
        (_, 2) => polygon(8 - 2 * (fold.unwrap_or(2) % 2)),
        _ => polygon(24),
    };
    Bus {
        section,
        half_length_m: 0.5 * length,
    }
}

/// The frame of a part sticking out of the bus along `radial(phi)` at
/// `x`: its base on the surface, and a rotation whose columns are x, the
/// outward direction and their cross product.
fn mount(bus: &Bus, phi: f64, x: f64) -> (Vector3<f64>, Rotation3<f64>) {
    let d = radial(phi);
    let base = Vector3::new(x, 0.0, 0.0) + d * bus.surface_radius(phi);
    let frame = Matrix3::from_columns(&[Vector3::x(), d, Vector3::x().cross(&d)]);
    (base, Rotation3::from_matrix_unchecked(frame))
}

/// A solar wing of `panels` hinged panels at `phi` and `x`: a yoke, then
/// panels of `width` (along x) by `length` (outward).
pub struct Wing {
    /// Panels.
    pub panels: u32,
    /// Panel width along x (m).
    pub width_m: f64,
    /// Panel length outward (m).
    pub length_m: f64,
    /// Yoke length (m).
    pub yoke_m: f64,
}

impl Wing {
    /// A wing sized to the bus, with the span of two wings kept within
    /// [`MAX_SPAN_M`].
    pub fn draw(rng: &mut ChaCha8Rng, bus: &Bus) -> Wing {
        let size = (2.0 * bus.half_length_m).max(2.0 * bus.outer_radius_m());
        let mut wing = Wing {
            panels: rng.random_range(1..=5),
            width_m: (2.0 * bus.half_length_m * rng.random_range(0.5..0.9)).clamp(0.4, 4.0),
            length_m: size * rng.random_range(0.4..1.0),
            yoke_m: size * rng.random_range(0.1..0.3),
        };
        while wing.panels > 1 && 2.0 * wing.reach_m(bus) > MAX_SPAN_M {
            wing.panels -= 1;
        }
        if 2.0 * wing.reach_m(bus) > MAX_SPAN_M {
            wing.length_m = 0.5 * MAX_SPAN_M - bus.outer_radius_m() - wing.yoke_m - HINGE_GAP_M;
        }
        wing
    }

    /// Distance of the wing's tip from the bus axis (m).
    pub fn reach_m(&self, bus: &Bus) -> f64 {
        bus.outer_radius_m() + self.yoke_m + f64::from(self.panels) * (self.length_m + HINGE_GAP_M)
    }

    /// The yoke and the panels at `phi`, `x`.
    pub fn add(&self, bus: &Bus, phi: f64, x: f64, parts: &mut Parts) -> Result<(), TargetError> {
        let (base, frame) = mount(bus, phi, x);
        let out = frame * Vector3::y();
        let yoke = 0.08;
        parts.meshes.push(cuboid(
            base + out * (0.5 * self.yoke_m),
            Vector3::new(yoke, self.yoke_m, yoke),
            frame,
            STRUCTURE,
        )?);
        for i in 0..self.panels {
            let along = self.yoke_m
                + HINGE_GAP_M
                + f64::from(i) * (self.length_m + HINGE_GAP_M)
                + 0.5 * self.length_m;
            parts.meshes.push(cuboid(
                base + out * along,
                Vector3::new(self.width_m, self.length_m, PANEL_THICKNESS_M),
                frame,
                SOLAR,
            )?);
        }
        Ok(())
    }

    /// Words for the description.
    pub fn describe(&self) -> String {
        format!(
            "{} panel(s) of {:.2} x {:.2} m",
            self.panels, self.width_m, self.length_m
        )
    }
}

/// What sticks out of the bus sideways.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Appendage {
    /// A boom of this length (m).
    Boom(f64),
    /// An instrument box of this edge (m).
    Instrument(f64),
    /// A dish of this rim radius (m) on a mast.
    Dish(f64),
}

impl Appendage {
    /// An appendage sized to the bus.
    pub fn draw(rng: &mut ChaCha8Rng, bus: &Bus) -> Appendage {
        let r = bus.inner_radius_m();
        match rng.random_range(0..3u32) {
            0 => Appendage::Boom(r * rng.random_range(1.0..3.0)),
            1 => Appendage::Instrument(r * rng.random_range(0.25..0.6)),
            _ => Appendage::Dish(r * rng.random_range(0.3..0.7)),
        }
    }

    /// The appendage at `phi`, `x` on the bus.
    pub fn add(&self, bus: &Bus, phi: f64, x: f64, parts: &mut Parts) -> Result<(), TargetError> {
        let (base, frame) = mount(bus, phi, x);
        let out = frame * Vector3::y();
        match *self {
            Appendage::Boom(length) => {
                let radius = (0.01 * length).max(0.03);
                parts
                    .meshes
                    .push(frustum(base, &out, length, [radius; 2], 8, 0.0, STRUCTURE)?);
                parts.meshes.push(cuboid(
                    base + out * length,
                    Vector3::repeat(6.0 * radius),
                    frame,
                    STRUCTURE,
                )?);
            }
            Appendage::Instrument(edge) => parts.meshes.push(cuboid(
                base + out * (0.5 * edge),
                Vector3::new(edge, edge, 0.8 * edge),
                frame,
                STRUCTURE,
            )?),
            Appendage::Dish(radius) => {
                let mast = 0.6 * radius;
                parts
                    .meshes
                    .push(frustum(base, &out, mast, [0.04; 2], 8, 0.0, STRUCTURE)?);
                parts.meshes.push(dish(
                    base + out * mast,
                    &out,
                    radius,
                    0.25 * radius,
                    ALUMINIUM,
                )?);
            }
        }
        Ok(())
    }

    /// Words for the description.
    pub fn describe(&self) -> String {
        match *self {
            Appendage::Boom(l) => format!("{l:.2} m boom"),
            Appendage::Instrument(e) => format!("{e:.2} m instrument box"),
            Appendage::Dish(r) => format!("{:.2} m dish", 2.0 * r),
        }
    }
}

/// Parts on the body axis: a dish at +x and a nozzle at -x, each drawn
/// with a probability, their polygons of 12 or 24 sides (exactly 2-, 3-
/// and 4-fold); `offset` moves them off the axis (0 keeps every
/// turn about x a symmetry).
pub fn add_axial(
    rng: &mut ChaCha8Rng,
    bus: &Bus,
    offset: Vector3<f64>,
    parts: &mut Parts,
) -> Result<(), TargetError> {
    let l = bus.half_length_m;
    let r = bus.inner_radius_m();
    if rng.random_bool(0.6) {
        let radius = r * rng.random_range(0.4..0.9);
        let mast = 0.3 * radius;
        let base = Vector3::new(l, 0.0, 0.0) + offset;
        parts.meshes.push(frustum(
            base,
            &Vector3::x(),
            mast,
            [0.05; 2],
            12,
            0.0,
            STRUCTURE,
        )?);
        let vertex = base + Vector3::x() * mast;
        parts.meshes.push(dish(
            vertex,
            &Vector3::x(),
            radius,
            0.25 * radius,
            ALUMINIUM,
        )?);
        parts
            .words
            .push(format!("{:.2} m dish on +x", 2.0 * radius));
    }
    if rng.random_bool(0.5) {
        let length = r * rng.random_range(0.5..1.0);
        let throat = 0.2 * r;
        let base = Vector3::new(-l, 0.0, 0.0) + offset;
        parts.meshes.push(frustum(
            base,
            &-Vector3::x(),
            length,
            [throat, 2.0 * throat],
            12,
            0.0,
            STRUCTURE,
        )?);
        parts.words.push(format!("{length:.2} m nozzle on -x"));
    }
    Ok(())
}

/// `count` angles `phi0 + 2πk/count`.
pub fn fold_angles(phi0: f64, count: u32) -> impl Iterator<Item = f64> {
    (0..count).map(move |k| phi0 + TAU * f64::from(k) / f64::from(count))
}

/// A random angle that is not within 20° of `phi` modulo π.
pub fn angle_away_from(rng: &mut ChaCha8Rng, phi: f64) -> f64 {
    loop {
        let a = rng.random_range(0.0..TAU);
        let off = (a - phi).rem_euclid(PI);
        if off.min(PI - off) > 20f64.to_radians() {
            return a;
        }
    }
}
