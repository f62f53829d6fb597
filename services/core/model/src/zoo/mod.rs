//! A procedural target zoo (issue 24 item 7): plausible spacecraft drawn
//! from a seed, to test generality on shapes nobody tuned on.
//!
//! A design is a bus (box, cylinder or regular prism; largest dimension
//! 1-8 m, covered in MLI), 0-2 solar wings of 1-5 hinged panels (span at
//! most 30 m), and appendages: dishes, booms, instrument boxes, nozzles.
//! The seed picks the intent, in turn: `seed % 3 == 0` exactly symmetric
//! (every part repeats under a 2-, 3- or 4-fold turn about body x),
//! `1` nearly symmetric (the same with one small box that breaks it), `2`
//! not symmetric. The intent is what the design was built to have; the
//! package's group is still detected from the mesh.
//!
//! Decision: no public model collection can be reached from this machine,
//! so the generality targets are generated; [`ZOO_VERSION`] changes with
//! any change of the draws, so a seed names one mesh per version.

mod bus;
mod design;
mod parts;

pub use bus::{Bus, Section};
pub use design::{Appendage, Intent, MAX_SPAN_M, Wing};

use crate::error::TargetError;
use crate::material::{
    ALUMINIUM_REFLECTANCE, MEAN_REFLECTANCE, MLI_REFLECTANCE, Material, MaterialClass,
    SOLAR_CELL_REFLECTANCE,
};
use crate::mesh::Mesh;
use crate::target::Target;
use design::{Parts, add_axial, angle_away_from, draw_bus, fold_angles};
use nalgebra::{Rotation3, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// Version of the generator's draws.
pub const ZOO_VERSION: u32 = 1;

/// A generated target and what it was built to be.
pub struct ZooTarget {
    /// The target (origin at the area-weighted centroid, the symmetry group
    /// the identity alone until detected).
    pub target: Target,
    /// The intended symmetry.
    pub intent: Intent,
    /// One line saying what was drawn.
    pub description: String,
}

/// The materials of every generated target, by the ids of `parts`.
pub fn materials() -> Vec<Material> {
    vec![
        Material::of_class("mli", MaterialClass::Mli, MLI_REFLECTANCE),
        Material::of_class(
            "solar cell",
            MaterialClass::SolarPanel,
            SOLAR_CELL_REFLECTANCE,
        ),
        Material::of_class("structure", MaterialClass::Structure, MEAN_REFLECTANCE),
        Material::of_class("aluminium", MaterialClass::Aluminium, ALUMINIUM_REFLECTANCE),
    ]
}

/// The intent of `seed` (see the module documentation).
pub fn intent_of(seed: u64, rng: &mut ChaCha8Rng) -> Intent {
    let fold = rng.random_range(2..=4u32);
    match seed % 3 {
        0 => Intent::Exact { fold },
        1 => Intent::Near { fold },
        _ => Intent::Asymmetric,
    }
}

/// Generates the spacecraft of `seed`.
pub fn generate(seed: u64) -> Result<ZooTarget, TargetError> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x7a6f_6f00_0000_0000);
    let intent = intent_of(seed, &mut rng);
    let fold = match intent {
        Intent::Exact { fold } | Intent::Near { fold } => Some(fold),
        Intent::Asymmetric => None,
    };
    let bus = draw_bus(&mut rng, fold);
    let mut parts = Parts {
        meshes: vec![bus.mesh()?],
        words: vec![bus.describe()],
    };
    match fold {
        Some(fold) => symmetric_parts(&mut rng, &bus, fold, &mut parts)?,
        None => asymmetric_parts(&mut rng, &bus, &mut parts)?,
    }
    if let Intent::Near { .. } = intent {
        let edge = bus.inner_radius_m() * rng.random_range(0.2..0.35);
        let x = bus.half_length_m * rng.random_range(-0.7..0.7);
        let phi = rng.random_range(0.0..TAU);
        Appendage::Instrument(edge).add(&bus, phi, x, &mut parts)?;
        parts
            .words
            .push(format!("one {edge:.2} m box breaking the symmetry"));
    }
    let mesh = Mesh::merged(&parts.meshes)?;
    let centroid = mesh.area_weighted_centroid();
    let mesh = mesh.transformed(&Rotation3::identity(), &-centroid)?;
    let name = format!("zoo-{seed}");
    let target = Target::new(&name, mesh, materials(), vec![Rotation3::identity()])?;
    let description = format!(
        "{name} (generator v{ZOO_VERSION}, {}): {}",
        describe_intent(intent),
        parts.words.join(", ")
    );
    Ok(ZooTarget {
        target,
        intent,
        description,
    })
}

fn describe_intent(intent: Intent) -> String {
    match intent {
        Intent::Exact { fold } => format!("exactly {fold}-fold symmetric about x"),
        Intent::Near { fold } => format!("nearly {fold}-fold symmetric about x"),
        Intent::Asymmetric => "not symmetric".to_owned(),
    }
}

/// Wings (only for a 2-fold design: two identical, opposite) and `fold`
/// copies of one appendage, all at `phi0 + 2πk/fold`, and axial parts.
fn symmetric_parts(
    rng: &mut ChaCha8Rng,
    bus: &Bus,
    fold: u32,
    parts: &mut Parts,
) -> Result<(), TargetError> {
    let phi0 = rng.random_range(0.0..TAU);
    let x = bus.half_length_m * rng.random_range(-0.3..0.3);
    if fold == 2 && rng.random_bool(0.7) {
        let wing = Wing::draw(rng, bus);
        for phi in fold_angles(phi0, 2) {
            wing.add(bus, phi, x, parts)?;
        }
        parts.words.push(format!(
            "2 wings of {} (span {:.1} m)",
            wing.describe(),
            2.0 * wing.reach_m(bus)
        ));
    }
    let appendage = Appendage::draw(rng, bus);
    let phi1 = phi0 + TAU / f64::from(2 * fold);
    let xa = bus.half_length_m * rng.random_range(-0.7..0.7);
    for phi in fold_angles(phi1, fold) {
        appendage.add(bus, phi, xa, parts)?;
    }
    parts
        .words
        .push(format!("{fold} x {}", appendage.describe()));
    add_axial(rng, bus, Vector3::zeros(), parts)
}

/// 0-2 wings that do not mirror each other, 1-3 appendages at random
/// places, and axial parts off the axis.
fn asymmetric_parts(rng: &mut ChaCha8Rng, bus: &Bus, parts: &mut Parts) -> Result<(), TargetError> {
    let phi0 = rng.random_range(0.0..TAU);
    let wings = rng.random_range(0..=2u32);
    let x = bus.half_length_m * rng.random_range(-0.4..0.4);
    let mut words = Vec::new();
    for k in 0..wings {
        let wing = Wing::draw(rng, bus);
        // The second wing is not opposite the first: 110-160° away.
        let phi = phi0 + f64::from(k) * rng.random_range(110f64..160.0).to_radians();
        wing.add(bus, phi, x, parts)?;
        words.push(wing.describe());
    }
    if wings > 0 {
        parts
            .words
            .push(format!("{wings} wing(s): {}", words.join("; ")));
    }
    for _ in 0..rng.random_range(1..=3u32) {
        let appendage = Appendage::draw(rng, bus);
        let phi = angle_away_from(rng, phi0);
        let xa = bus.half_length_m * rng.random_range(-0.8..0.8);
        appendage.add(bus, phi, xa, parts)?;
        parts.words.push(appendage.describe());
    }
    let r = bus.inner_radius_m() * 0.4;
    let offset = Vector3::new(0.0, r * rng.random_range(-1.0..1.0), r);
    add_axial(rng, bus, offset, parts)
}

#[cfg(test)]
mod tests;
