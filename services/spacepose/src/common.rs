//! Helpers shared by sub-commands.

use anyhow::{Context, Result, bail};
use spacepose_target::Target;
use std::sync::Arc;

/// A built-in target by name, or a mesh file scaled to metres.
pub fn load_target(spec: &str, scale: f64) -> Result<Arc<Target>> {
    if !(scale.is_finite() && scale > 0.0) {
        bail!("--scale must be a positive number, got {scale}");
    }
    let target = Target::resolve(spec, scale).with_context(|| {
        format!(
            "cannot load target {spec:?} (built-in targets: {})",
            Target::BUILTIN.join(", ")
        )
    })?;
    Ok(Arc::new(target))
}
