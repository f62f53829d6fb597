//! The dependency graph of the workspace, from `cargo metadata`.

use serde_json::Value;
use std::collections::{BTreeMap, VecDeque};
use std::path::{Path, PathBuf};
use std::process::Command;

/// One package of the resolved graph.
#[derive(Debug, Clone)]
pub struct Package {
    /// Crate name (`spacepose-tracker`, `zenoh`, ...).
    pub name: String,
    /// Its `Cargo.toml`.
    pub manifest: PathBuf,
    /// Ids of its dependencies, each with whether it is a dev-dependency
    /// only.
    pub deps: Vec<(String, bool)>,
    /// Its targets: `(kind, root source file)` (`lib`, `bin`, `test`, ...).
    pub targets: Vec<(String, PathBuf)>,
}

/// The workspace's resolved dependency graph.
#[derive(Debug, Clone)]
pub struct Metadata {
    /// Packages by id.
    pub packages: BTreeMap<String, Package>,
    /// Ids of the workspace members.
    pub members: Vec<String>,
}

impl Metadata {
    /// Runs `cargo metadata` in `root` (the cargo of the running build when
    /// `CARGO` is set) for the host platform: what builds here, with
    /// nothing to download.
    pub fn load(root: &Path) -> Result<Metadata, String> {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let host = host_triple()?;
        let out = Command::new(cargo)
            .args(["metadata", "--format-version", "1", "--offline"])
            .args(["--filter-platform", &host])
            .current_dir(root)
            .output()
            .map_err(|e| format!("cargo metadata: {e}"))?;
        if !out.status.success() {
            return Err(String::from_utf8_lossy(&out.stderr).into_owned());
        }
        let v: Value = serde_json::from_slice(&out.stdout).map_err(|e| e.to_string())?;
        Metadata::parse(&v)
    }

    /// Reads the JSON of `cargo metadata --format-version 1`.
    pub fn parse(v: &Value) -> Result<Metadata, String> {
        let str_of = |v: &Value, k: &str| v[k].as_str().map(str::to_string);
        let mut packages = BTreeMap::new();
        for p in v["packages"].as_array().ok_or("no packages")? {
            let id = str_of(p, "id").ok_or("package without id")?;
            let package = Package {
                name: str_of(p, "name").ok_or("package without name")?,
                manifest: str_of(p, "manifest_path").unwrap_or_default().into(),
                deps: Vec::new(),
                targets: p["targets"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .filter_map(|t| {
                        let kind = t["kind"].as_array()?.first()?.as_str()?.to_string();
                        Some((kind, str_of(t, "src_path")?.into()))
                    })
                    .collect(),
            };
            packages.insert(id, package);
        }
        for node in v["resolve"]["nodes"].as_array().ok_or("no resolve graph")? {
            let id = str_of(node, "id").ok_or("node without id")?;
            let deps = node["deps"].as_array().cloned().unwrap_or_default();
            let edges = deps.iter().filter_map(|d| {
                let kinds = d["dep_kinds"].as_array()?;
                let dev_only = kinds.iter().all(|k| k["kind"].as_str() == Some("dev"));
                Some((str_of(d, "pkg")?, dev_only))
            });
            if let Some(p) = packages.get_mut(&id) {
                p.deps = edges.collect();
            }
        }
        let members = v["workspace_members"]
            .as_array()
            .ok_or("no workspace members")?
            .iter()
            .filter_map(|m| m.as_str().map(str::to_string))
            .collect();
        Ok(Metadata { packages, members })
    }

    /// The workspace members whose manifest lies below `dir`.
    pub fn members_under(&self, dir: &Path) -> Vec<&str> {
        self.members
            .iter()
            .filter(|id| self.packages[*id].manifest.starts_with(dir))
            .map(String::as_str)
            .collect()
    }
}

/// The host's target triple (`rustc -vV`).
fn host_triple() -> Result<String, String> {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let out = Command::new(rustc)
        .arg("-vV")
        .output()
        .map_err(|e| format!("rustc -vV: {e}"))?;
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .find_map(|l| l.strip_prefix("host: "))
        .map(str::to_string)
        .ok_or_else(|| "rustc -vV names no host".into())
}

/// For the package `id`, the shortest dependency chain (crate names, the
/// package first) to every package whose name `forbidden` accepts.
/// Dev-dependencies of `id` itself count when `with_dev` is set; those of
/// its dependencies never do (they do not reach its build).
pub fn forbidden_paths(
    meta: &Metadata,
    id: &str,
    with_dev: bool,
    forbidden: impl Fn(&str) -> bool,
) -> Vec<Vec<String>> {
    let mut came_from: BTreeMap<&str, &str> = BTreeMap::new();
    let mut queue = VecDeque::from([id]);
    let mut found = Vec::new();
    while let Some(cur) = queue.pop_front() {
        let Some(p) = meta.packages.get(cur) else {
            continue;
        };
        if cur != id && forbidden(&p.name) {
            found.push(chain(meta, &came_from, id, cur));
            continue;
        }
        for (dep, dev_only) in &p.deps {
            let allowed = !dev_only || (with_dev && cur == id);
            if allowed && dep != id && !came_from.contains_key(dep.as_str()) {
                came_from.insert(dep, cur);
                queue.push_back(dep);
            }
        }
    }
    found
}

fn chain(meta: &Metadata, came_from: &BTreeMap<&str, &str>, from: &str, to: &str) -> Vec<String> {
    let mut names = vec![meta.packages[to].name.clone()];
    let mut cur = to;
    while cur != from {
        cur = came_from[cur];
        names.push(meta.packages[cur].name.clone());
    }
    names.reverse();
    names
}

#[cfg(test)]
mod tests {
    use super::*;

    fn meta() -> Metadata {
        let v = serde_json::json!({
            "packages": [
                {"id": "a", "name": "algo", "manifest_path": "/r/services/core/algo/Cargo.toml"},
                {"id": "b", "name": "helper", "manifest_path": "/r/services/core/helper/Cargo.toml"},
                {"id": "z", "name": "zenoh", "manifest_path": "/reg/zenoh/Cargo.toml"},
                {"id": "t", "name": "tempfile", "manifest_path": "/reg/tempfile/Cargo.toml"}
            ],
            "workspace_members": ["a", "b"],
            "resolve": {"nodes": [
                {"id": "a", "deps": [{"pkg": "b", "dep_kinds": [{"kind": null}]},
                                     {"pkg": "t", "dep_kinds": [{"kind": "dev"}]}]},
                {"id": "b", "deps": [{"pkg": "z", "dep_kinds": [{"kind": null}]}]},
                {"id": "z", "deps": []},
                {"id": "t", "deps": []}
            ]}
        });
        Metadata::parse(&v).unwrap()
    }

    #[test]
    fn a_transitive_dependency_is_found_with_its_chain() {
        let m = meta();
        let paths = forbidden_paths(&m, "a", false, |n| n.starts_with("zenoh"));
        assert_eq!(paths, vec![vec!["algo", "helper", "zenoh"]]);
        assert!(forbidden_paths(&m, "a", false, |n| n == "tempfile").is_empty());
        assert_eq!(
            forbidden_paths(&m, "a", true, |n| n == "tempfile"),
            vec![vec!["algo", "tempfile"]]
        );
        assert_eq!(m.members_under(Path::new("/r/services/core")), ["a", "b"]);
    }
}
