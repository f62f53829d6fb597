//! What the recorder writes besides the messages: the target mesh, the
//! descriptor and the services' configurations, and where the file goes.

use anyhow::Context;
use spacepose_foxglove::{Recorder, TargetMesh};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// `path` when it does not exist, else the first free `<stem>.<n>.mcap`
/// beside it (a restarted recorder never overwrites the part before).
pub fn free_path(path: &Path) -> PathBuf {
    if !path.exists() {
        return path.to_path_buf();
    }
    let stem = path
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    (1u32..)
        .map(|n| path.with_file_name(format!("{stem}.{n}.mcap")))
        .find(|p| !p.exists())
        .unwrap_or_else(|| path.to_path_buf())
}

/// The mesh of the target `spec` (as the tracker resolves it), in its body frame.
///
/// # Errors
/// The target cannot be resolved.
pub fn target_mesh(spec: &str, scale: f64) -> anyhow::Result<TargetMesh> {
    let package = spacepose_prepare::resolve(spec, scale)
        .with_context(|| format!("target {spec:?} for the recorded scene"))?;
    Ok(TargetMesh::of(&package.target))
}

/// Records the descriptor as the attachment `descriptor.toml`, and each
/// `[[service]]`'s kind and configuration as the metadata record
/// `spacepose.config.<instance>` (keys `kind`, `config.toml`).
///
/// # Errors
/// The descriptor is not TOML, or the file could not be written.
pub fn record_descriptor(rec: &Recorder, descriptor: &str) -> anyhow::Result<()> {
    rec.attach("descriptor.toml", "application/toml", descriptor.as_bytes())?;
    let table: toml::Table = toml::from_str(descriptor).context("the descriptor")?;
    let services = table
        .get("service")
        .and_then(toml::Value::as_array)
        .map_or(&[][..], Vec::as_slice);
    for s in services.iter().filter_map(toml::Value::as_table) {
        let field = |k: &str| s.get(k).and_then(toml::Value::as_str).unwrap_or("");
        let config = match s.get("config").and_then(toml::Value::as_table) {
            Some(c) => toml::to_string(c).context("a service configuration")?,
            None => String::new(),
        };
        let entries = BTreeMap::from([
            ("kind".to_string(), field("kind").to_string()),
            ("config.toml".to_string(), config),
        ]);
        rec.metadata(&format!("spacepose.config.{}", field("name")), entries)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_taken_path_moves_to_the_next_free_part() {
        let dir = tempfile::tempdir().unwrap();
        let run = dir.path().join("run.mcap");
        assert_eq!(free_path(&run), run);
        std::fs::write(&run, b"x").unwrap();
        assert_eq!(free_path(&run), dir.path().join("run.1.mcap"));
        std::fs::write(dir.path().join("run.1.mcap"), b"x").unwrap();
        assert_eq!(free_path(&run), dir.path().join("run.2.mcap"));
    }

    #[test]
    fn the_builtin_target_has_a_closed_mesh_and_bad_targets_are_named() {
        let mesh = target_mesh("deos", 1.0).unwrap();
        assert_eq!(mesh.name, "deos");
        assert!(mesh.triangles.len() > 10);
        let n = mesh.vertices.len() as u32;
        assert!(mesh.triangles.iter().flatten().all(|&i| i < n));
        let e = format!("{:#}", target_mesh("/nonexistent/x.stl", 1.0).unwrap_err());
        assert!(e.contains("x.stl"), "{e}");
    }
}
