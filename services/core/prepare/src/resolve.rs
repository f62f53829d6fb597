//! What a user writes where a target is expected, as a loaded package:
//! - a package directory (holding `target.toml`): loaded as it is;
//! - a built-in name (`deos`, `envisat`) at scale 1: the built-in target
//!   with the manifest of its committed package (`deploy/targets/<name>/`,
//!   built by `spacepose target prepare <name>`), embedded at compile time
//!   so that a binary needs no file to run on a built-in target;
//! - a mesh file (or a built-in at another scale): prepared on first use
//!   into the cache ([`cache_dir`]) and loaded from there afterwards; the
//!   cache entry is keyed by the FNV-1a of the source bytes and the scale,
//!   so an edited mesh is prepared again;
//! - `zoo:N`: the generated spacecraft of seed N
//!   (`spacepose_model::zoo`), prepared on first use into the cache like a
//!   mesh file.

use crate::error::PrepareError;
use crate::prepare::{PrepareOptions, load_source, prepare};
use spacepose_model::Target;
use spacepose_model::package::{TargetPackage, is_package_dir, load_package};
use std::path::{Path, PathBuf};

/// Resolves `spec` (see the module documentation), preparing into
/// [`cache_dir`] when needed.
pub fn resolve(spec: &str, scale: f64) -> Result<TargetPackage, PrepareError> {
    resolve_with(spec, scale, cache_dir)
}

/// [`resolve`] with an explicit cache directory.
pub fn resolve_in(spec: &str, scale: f64, cache: &Path) -> Result<TargetPackage, PrepareError> {
    resolve_with(spec, scale, || Ok(cache.to_owned()))
}

/// [`resolve`], asking for the cache directory only when a mesh file or a
/// generated design must be prepared (a package directory or a built-in
/// needs none).
fn resolve_with(
    spec: &str,
    scale: f64,
    cache: impl FnOnce() -> Result<PathBuf, PrepareError>,
) -> Result<TargetPackage, PrepareError> {
    let path = Path::new(spec);
    if is_package_dir(path) {
        return load_dir(path, scale);
    }
    if let Some(package) = builtin_package(spec, scale)? {
        return Ok(package);
    }
    let (target, _, fnv) = load_source(spec, scale)?;
    let entry = cache()?
        .join("targets")
        .join(format!("{}-{fnv:016x}", target.name()));
    if is_package_dir(&entry) {
        let package = load_package(&entry)?;
        if package.manifest.provenance.source_fnv64 == format!("{fnv:016x}") {
            return Ok(package);
        }
    }
    tracing::info!(
        "preparing target package for {spec} into {} (once; `spacepose target prepare` does it ahead)",
        entry.display()
    );
    prepare_into(spec, scale, &entry)
}

/// The embedded package of a built-in target at scale 1 (`None` when
/// `spec` is not a built-in name or the scale is not 1).
pub fn builtin_package(spec: &str, scale: f64) -> Result<Option<TargetPackage>, PrepareError> {
    let Some(text) = embedded_manifest(spec) else {
        return Ok(None);
    };
    if scale != 1.0 {
        return Ok(None);
    }
    let target = Target::builtin(spec)?;
    let manifest = spacepose_model::package::parse_manifest(text)?;
    let target = target.with_symmetries(
        &manifest.name,
        manifest.symmetry.group(),
        manifest.symmetry.twins(),
    )?;
    Ok(Some(TargetPackage {
        target,
        manifest,
        dir: None,
    }))
}

/// The committed manifests of the built-in targets.
fn embedded_manifest(name: &str) -> Option<&'static str> {
    match name {
        "deos" => Some(include_str!("../../../../deploy/targets/deos/target.toml")),
        "envisat" => Some(include_str!(
            "../../../../deploy/targets/envisat/target.toml"
        )),
        _ => None,
    }
}

/// Where packages prepared on the fly are kept: `$SPACEPOSE_CACHE_DIR`,
/// else `$XDG_CACHE_HOME/spacepose`, else `$HOME/.cache/spacepose`.
pub fn cache_dir() -> Result<PathBuf, PrepareError> {
    let var = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("SPACEPOSE_CACHE_DIR")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("spacepose")))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("spacepose")))
        .ok_or_else(|| {
            PrepareError::InvalidOption(
                "no cache directory: set SPACEPOSE_CACHE_DIR, or prepare the target with \
                 `spacepose target prepare` and give the package directory"
                    .into(),
            )
        })
}

fn load_dir(path: &Path, scale: f64) -> Result<TargetPackage, PrepareError> {
    if scale != 1.0 {
        return Err(PrepareError::InvalidOption(format!(
            "{}: a package is already in metres; target_scale = {scale} applies to mesh files only",
            path.display()
        )));
    }
    Ok(load_package(path)?)
}

/// Prepares into a private directory, then renames it into place, so
/// services starting together never read a half-written package (the
/// loser of a race loads the winner's).
fn prepare_into(spec: &str, scale: f64, entry: &Path) -> Result<TargetPackage, PrepareError> {
    let io = |path: &Path, e: std::io::Error| PrepareError::Io {
        path: path.to_owned(),
        message: e.to_string(),
    };
    let parent = entry.parent().unwrap_or(entry);
    std::fs::create_dir_all(parent).map_err(|e| io(parent, e))?;
    let tmp = parent.join(format!(".tmp-{}-{}", std::process::id(), unique()));
    let options = PrepareOptions {
        scale,
        command: format!("spacepose target prepare {spec} --scale {scale} (on first use)"),
        ..PrepareOptions::default()
    };
    prepare(spec, &options, Some(&tmp), &mut |_, _| {})?;
    if std::fs::rename(&tmp, entry).is_err() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    Ok(load_package(entry)?)
}

fn unique() -> u128 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos())
}
