//! Helpers shared by sub-commands.

use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use spacepose_model::Target;
use std::sync::Arc;

/// A target package: a built-in name, a package directory, or a mesh file
/// scaled to metres (prepared on first use, `spacepose_prepare::resolve`).
pub fn load_target(spec: &str, scale: f64) -> Result<Arc<Target>> {
    if !(scale.is_finite() && scale > 0.0) {
        bail!("--scale must be a positive number, got {scale}");
    }
    let package = spacepose_prepare::resolve(spec, scale).with_context(|| {
        format!(
            "cannot load target {spec:?} (built-in targets: {}; or a package directory or a \
             mesh file)",
            Target::BUILTIN.join(", ")
        )
    })?;
    Ok(Arc::new(package.target))
}

/// A progress bar on stderr (hidden when stderr is not a terminal).
pub fn progress_bar(len: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    let style = ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} frames ({eta})")
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
    bar.set_style(style);
    bar.set_message(what.to_string());
    bar
}
