//! The rules of the house, from `cargo metadata` and the sources:
//! algorithm libraries never reach a bus crate, service mains are short,
//! production files are at most 400 lines, and no crate has an import
//! circle between its files. `cargo run -p spacepose-e2e --example layout`
//! prints the same measurements.

use spacepose_e2e::layout::{CrateModules, Metadata, circles, forbidden_paths, line_count};
use spacepose_e2e::repo_root;
use std::path::{Path, PathBuf};

/// The crates an algorithm library must not reach, even transitively.
fn is_bus_crate(name: &str) -> bool {
    name.starts_with("iceoryx2")
        || name.starts_with("zenoh")
        || matches!(
            name,
            "spacepose-bus" | "spacepose-messages" | "spacepose-runtime"
        )
}

fn metadata() -> Metadata {
    Metadata::load(&repo_root()).expect("cargo metadata runs offline")
}

/// `(crate name, target kind, root source file)` of every lib and bin
/// target of the workspace.
fn lib_and_bin_targets(meta: &Metadata) -> Vec<(String, String, PathBuf)> {
    meta.members
        .iter()
        .flat_map(|id| {
            let p = &meta.packages[id];
            p.targets
                .iter()
                .filter(|(kind, _)| kind == "lib" || kind == "bin")
                .map(|(kind, src)| (p.name.clone(), kind.clone(), src.clone()))
        })
        .collect()
}

fn relative(path: &Path) -> String {
    let root = repo_root();
    path.strip_prefix(&root)
        .unwrap_or(path)
        .display()
        .to_string()
}

#[test]
fn algorithm_libraries_reach_no_bus_crate() {
    let meta = metadata();
    let core = meta.members_under(&repo_root().join("services").join("core"));
    assert!(
        core.len() >= 10,
        "only {} crates under services/core",
        core.len()
    );
    let mut reached = Vec::new();
    for id in core {
        for path in forbidden_paths(&meta, id, false, is_bus_crate) {
            reached.push(path.join(" -> "));
        }
    }
    assert!(
        reached.is_empty(),
        "bus crates reached:\n{}",
        reached.join("\n")
    );
}

#[test]
fn service_mains_are_at_most_40_lines() {
    let meta = metadata();
    let nodes = repo_root().join("services").join("nodes");
    let mains: Vec<(String, usize)> = lib_and_bin_targets(&meta)
        .into_iter()
        .filter(|(_, kind, src)| kind == "bin" && src.starts_with(&nodes))
        .map(|(_, _, src)| (relative(&src), line_count(&src)))
        .collect();
    assert!(mains.len() >= 8, "only {} service mains", mains.len());
    let long: Vec<_> = mains.iter().filter(|(_, n)| *n > 40).collect();
    assert!(long.is_empty(), "service mains over 40 lines: {long:?}");
}

#[test]
fn production_files_are_at_most_400_lines() {
    let meta = metadata();
    let mut long = Vec::new();
    let mut files = 0;
    for (_, _, src) in lib_and_bin_targets(&meta) {
        let modules = CrateModules::load(&src).expect("the crate's modules parse");
        for f in modules.production_files() {
            files += 1;
            let n = line_count(f);
            if n > 400 {
                long.push(format!("{n} lines: {}", relative(f)));
            }
        }
    }
    assert!(files > 100, "only {files} production files found");
    long.sort();
    long.dedup();
    assert!(long.is_empty(), "{}", long.join("\n"));
}

#[test]
fn no_crate_has_an_import_circle() {
    let meta = metadata();
    let mut found = Vec::new();
    for (name, kind, src) in lib_and_bin_targets(&meta) {
        let modules = CrateModules::load(&src).expect("the crate's modules parse");
        for circle in circles(&modules) {
            let files: Vec<String> = circle.iter().map(|f| relative(f)).collect();
            found.push(format!("{name} ({kind}): {}", files.join(" ")));
        }
    }
    assert!(found.is_empty(), "import circles:\n{}", found.join("\n"));
}
