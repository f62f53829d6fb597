//! The shape of the house, measured: which crates an algorithm library
//! reaches (from `cargo metadata`), how long production files and service
//! mains are, and the import circles between the modules of one crate.
//!
//! `tests/tests/layout.rs` turns these measurements into the rules of
//! `docs/architecture.md`; `cargo run -p spacepose-e2e --example layout`
//! prints them.

pub mod deps;
pub mod modules;

pub use deps::{Metadata, forbidden_paths};
pub use modules::{CrateModules, ModuleFile, circles};

use std::path::{Path, PathBuf};

/// Every `.rs` file below `dir`, sorted, skipping `target` folders.
pub fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                if p.file_name().is_some_and(|n| n != "target") {
                    stack.push(p);
                }
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Lines in a file (0 when it cannot be read).
pub fn line_count(path: &Path) -> usize {
    std::fs::read_to_string(path).map_or(0, |s| s.lines().count())
}
