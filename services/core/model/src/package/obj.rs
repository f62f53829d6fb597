//! The package mesh file: a Wavefront OBJ subset written and read exactly
//! (f64 shortest round-trip decimals, so a package reloads bit for bit).
//!
//! Written: `v x y z` lines, then the faces `f a b c` in the mesh's order
//! (1-based, global vertex indices), an object line `o material_<id>`
//! starting each run of faces of one material. Read: exactly that subset plus `#` comments and blank
//! lines; anything else is an error naming the line (a user's own OBJ
//! files go through the general loader, not this one).

use crate::error::TargetError;
use crate::mesh::Mesh;
use nalgebra::Vector3;
use std::fmt::Write as _;

/// The OBJ text of a body-frame mesh.
pub(crate) fn to_obj(mesh: &Mesh, header: &str) -> String {
    let mut s = String::new();
    for line in header.lines() {
        let _ = writeln!(s, "# {line}");
    }
    for v in mesh.vertices() {
        let _ = writeln!(s, "v {} {} {}", v.x, v.y, v.z);
    }
    // Faces keep their order (so sampling and ray casting are the same as
    // on the source mesh); a new object line starts at each material change.
    let mut current = None;
    for (t, &id) in mesh.triangles().iter().zip(mesh.face_materials()) {
        if current != Some(id) {
            let _ = writeln!(s, "o material_{id}");
            current = Some(id);
        }
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

/// Parses what [`to_obj`] writes.
pub(crate) fn from_obj(text: &str) -> Result<Mesh, TargetError> {
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    let mut materials = Vec::new();
    let mut current: Option<u16> = None;
    for (n, line) in text.lines().enumerate() {
        let bad = |what: &str| TargetError::InvalidPackage(format!("mesh line {}: {what}", n + 1));
        let mut words = line.split_whitespace();
        match words.next() {
            None => {}
            Some(w) if w.starts_with('#') => {}
            Some("v") => vertices.push(Vector3::from(numbers::<f64>(words, &bad)?)),
            Some("o") => {
                let id = words
                    .next()
                    .and_then(|name| name.strip_prefix("material_"))
                    .and_then(|id| id.parse().ok())
                    .ok_or_else(|| bad("expected `o material_<id>`"))?;
                current = Some(id);
            }
            Some("f") => {
                let [a, b, c] = numbers::<u32>(words, &bad)?;
                if a == 0 || b == 0 || c == 0 {
                    return Err(bad("face index 0 (indices are 1-based)"));
                }
                triangles.push([a - 1, b - 1, c - 1]);
                materials.push(current.ok_or_else(|| bad("face before any `o material_<id>`"))?);
            }
            Some(other) => return Err(bad(&format!("unsupported statement `{other}`"))),
        }
    }
    Mesh::new(vertices, triangles, materials)
}

/// Exactly three numbers.
fn numbers<'a, T: std::str::FromStr>(
    mut words: impl Iterator<Item = &'a str>,
    bad: &dyn Fn(&str) -> TargetError,
) -> Result<[T; 3], TargetError> {
    let mut next = || {
        words
            .next()
            .and_then(|w| w.parse::<T>().ok())
            .ok_or_else(|| bad("expected three numbers"))
    };
    let out = [next()?, next()?, next()?];
    if words.next().is_some() {
        return Err(bad("more than three numbers"));
    }
    Ok(out)
}
