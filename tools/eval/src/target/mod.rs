//! `spacepose target`: target packages (crate `spacepose-prepare`).
//!
//! - `target prepare MESH|BUILTIN --out DIR`: loads the mesh, detects its
//!   symmetry group, calibrates its thresholds from simulated frames, and
//!   writes the package;
//! - `target generate --seed N --out DIR`: the generated spacecraft of
//!   seed N (`spacepose_model::zoo`), prepared the same way;
//! - `target show SPEC`: prints what a package (or a built-in, or a mesh
//!   prepared on the fly) records.

use crate::common::progress_bar;
use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use nalgebra::{Rotation3, Vector3};
use spacepose_model::package::TargetPackage;
use spacepose_model::symmetry::SymmetryOptions;
use spacepose_prepare::{PrepareOptions, SymmetryChoice};
use std::path::PathBuf;

/// Target packages.
#[derive(Debug, Subcommand)]
pub enum TargetCommand {
    /// Prepare a mesh (STL/OBJ/PLY) or a built-in target into a package
    /// directory that every service and command accepts as a target.
    Prepare(PrepareArgs),
    /// Print what a package, a built-in target or a mesh records.
    Show(ShowArgs),
    /// Generate a plausible spacecraft from a seed (the target zoo) and
    /// prepare it into a package; `zoo:N` names the same target anywhere.
    Generate(GenerateArgs),
}

/// `spacepose target generate`.
#[derive(Debug, Args)]
pub struct GenerateArgs {
    /// Seed of the design (`seed % 3`: 0 exactly symmetric, 1 nearly, 2 not).
    #[arg(long)]
    pub seed: u64,
    /// The package directory to write.
    #[arg(long)]
    pub out: PathBuf,
}

/// `spacepose target prepare`.
#[derive(Debug, Args)]
pub struct PrepareArgs {
    /// Mesh file, or a built-in name (`deos`, `envisat`).
    pub mesh: String,
    /// Scale from the file's units to metres (0.001 for millimetres).
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// Name of the target (default: the file stem or built-in name).
    #[arg(long)]
    pub name: Option<String>,
    /// The package directory to write.
    #[arg(long)]
    pub out: PathBuf,
    /// Symmetry tolerance, as a fraction of the bounding radius.
    #[arg(long)]
    pub symmetry_tolerance: Option<f64>,
    /// Override the detected group: rotation vectors `rx,ry,rz` in degrees
    /// (axis times angle), `;`-separated, identity implied
    /// (e.g. `120,0,0;-120,0,0`); `none` for the identity alone.
    #[arg(long)]
    pub symmetry: Option<String>,
}

/// `spacepose target show`.
#[derive(Debug, Args)]
pub struct ShowArgs {
    /// Package directory, built-in name or mesh file.
    pub spec: String,
    /// Scale of a mesh file.
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
}

/// Runs a `spacepose target` command.
pub fn run(command: &TargetCommand) -> Result<()> {
    match command {
        TargetCommand::Prepare(args) => prepare(args),
        TargetCommand::Generate(args) => prepare(&PrepareArgs {
            mesh: format!("zoo:{}", args.seed),
            scale: 1.0,
            name: None,
            out: args.out.clone(),
            symmetry_tolerance: None,
            symmetry: None,
        }),
        TargetCommand::Show(args) => {
            let package = spacepose_prepare::resolve(&args.spec, args.scale)
                .with_context(|| format!("target {}", args.spec))?;
            print!("{}", summary(&package));
            Ok(())
        }
    }
}

fn prepare(args: &PrepareArgs) -> Result<()> {
    let mut options = PrepareOptions {
        name: args.name.clone(),
        scale: args.scale,
        command: std::iter::once("spacepose".to_owned())
            .chain(std::env::args().skip(1))
            .collect::<Vec<_>>()
            .join(" "),
        ..PrepareOptions::default()
    };
    if let Some(tolerance) = args.symmetry_tolerance {
        let detect = SymmetryOptions {
            tolerance_fraction: tolerance,
            ..SymmetryOptions::default()
        };
        options.symmetry = SymmetryChoice::Detect(detect);
    }
    if let Some(text) = &args.symmetry {
        options.symmetry = SymmetryChoice::Override {
            group: parse_group(text)?,
            twins: Vec::new(),
        };
    }
    let bar = progress_bar(1, "calibration frames");
    let package = spacepose_prepare::prepare(&args.mesh, &options, Some(&args.out), &mut |d, t| {
        bar.set_length(t as u64);
        bar.set_position(d as u64);
    })
    .with_context(|| format!("preparing {}", args.mesh))?;
    bar.finish_and_clear();
    print!("{}", summary(&package));
    println!("written to {}", args.out.display());
    Ok(())
}

/// `--symmetry`: identity first, then the given rotations.
fn parse_group(text: &str) -> Result<Vec<Rotation3<f64>>> {
    let mut group = vec![Rotation3::identity()];
    if text.trim() == "none" {
        return Ok(group);
    }
    for item in text.split(';') {
        let v: Vec<f64> = item
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .with_context(|| format!("--symmetry: `{item}` is not rx,ry,rz in degrees"))?;
        let [x, y, z] = v[..] else {
            anyhow::bail!("--symmetry: `{item}` needs three numbers");
        };
        anyhow::ensure!(
            [x, y, z].iter().all(|c| c.is_finite()),
            "--symmetry: `{item}` is not finite"
        );
        group.push(Rotation3::new(Vector3::new(x, y, z).map(f64::to_radians)));
    }
    Ok(group)
}

/// A human-readable summary of a package.
pub fn summary(p: &TargetPackage) -> String {
    let m = &p.manifest;
    let g = &m.geometry;
    let c = &m.calibration;
    let deg = |r: &Rotation3<f64>| {
        let q = nalgebra::UnitQuaternion::from_rotation_matrix(r);
        let v = q.scaled_axis().map(f64::to_degrees);
        format!("[{:.1}, {:.1}, {:.1}]", v.x, v.y, v.z)
    };
    let design = if m.mesh.source.starts_with("zoo:") {
        format!("  design: {}\n", m.mesh.conventions)
    } else {
        String::new()
    };
    let group: Vec<String> = m.symmetry.group().iter().map(deg).collect();
    let twins: Vec<String> = m.symmetry.twins().iter().map(deg).collect();
    format!(
        "target {} ({})\n{design}  bounding radius {:.3} m, extent {:.2} x {:.2} x {:.2} m, {} triangles\n  \
         symmetry ({}): {} rotation(s) {}\n  twins: {}\n  calibration: max_mean_cost_ndt {:.2}, \
         min_inlier_fraction {:.3} ({} of {} frames; cost p50 {:.2}, p99 {:.2})\n",
        m.name,
        m.mesh.source,
        g.bounding_radius_m,
        g.extent_m[0],
        g.extent_m[1],
        g.extent_m[2],
        g.triangles,
        m.symmetry.source,
        group.len(),
        group.join(" "),
        if twins.is_empty() {
            "none".to_owned()
        } else {
            twins.join(" ")
        },
        c.max_mean_cost_ndt,
        c.min_inlier_fraction,
        c.record.frames_used,
        c.record.frames,
        c.record.mean_cost_p50,
        c.record.mean_cost_p99,
    )
}
