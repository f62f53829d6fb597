//! The walk over a crate's module tree: each file and inline module, the
//! items it defines, its re-exports and the paths its code names, and the
//! resolution of a named path to the module that defines the item.

use super::syntax::{PathCollector, attrs_of, flatten_use, is_test, item_name, path_attr};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use syn::visit::Visit;

/// One source file of the crate.
#[derive(Debug, Clone)]
pub struct ModuleFile {
    /// The file.
    pub file: PathBuf,
    /// Only compiled for tests.
    pub test: bool,
}

/// A module (file or inline) of the tree.
#[derive(Debug, Default, Clone)]
pub struct Module {
    /// The file it is in (index into `Walker::files`).
    pub file: usize,
    children: BTreeSet<String>,
    items: BTreeSet<String>,
    /// `pub use` bindings: name → path (as written).
    reexports: BTreeMap<String, Vec<String>>,
    globs: Vec<Vec<String>>,
    /// Private `use` bindings: name → path (as written), so a path that
    /// starts with an imported module name (`builtin::deos::target()` after
    /// `use crate::builtin;`) resolves through it.
    bindings: BTreeMap<String, Vec<String>>,
    /// Paths named by the module's own (non-test) code.
    pub uses: Vec<Vec<String>>,
}

/// The files and modules read so far, keyed by module path.
#[derive(Default)]
pub struct Walker {
    /// Files, the root first.
    pub files: Vec<ModuleFile>,
    /// Every module, by path from the crate root.
    pub modules: BTreeMap<Vec<String>, Module>,
}

impl Walker {
    /// Reads `file` as module `path`; `mod_rs`: its children live in its
    /// own directory (lib.rs, main.rs, mod.rs, or a `#[path]` file).
    pub fn file(
        &mut self,
        file: &Path,
        path: Vec<String>,
        test: bool,
        mod_rs: bool,
    ) -> Result<(), String> {
        let text = std::fs::read_to_string(file).map_err(|e| format!("{}: {e}", file.display()))?;
        let ast = syn::parse_file(&text).map_err(|e| format!("{}: {e}", file.display()))?;
        let index = self.files.len();
        self.files.push(ModuleFile {
            file: file.to_path_buf(),
            test,
        });
        let dir = if mod_rs {
            file.parent().map(Path::to_path_buf).unwrap_or_default()
        } else {
            file.with_extension("")
        };
        let facade = mod_rs;
        self.items(&ast.items, path, index, test, &dir, file, facade)
    }

    #[allow(clippy::too_many_arguments)]
    fn items(
        &mut self,
        items: &[syn::Item],
        path: Vec<String>,
        file: usize,
        test: bool,
        dir: &Path,
        file_path: &Path,
        facade: bool,
    ) -> Result<(), String> {
        self.modules.entry(path.clone()).or_default().file = file;
        for item in items {
            if is_test(attrs_of(item)) {
                continue;
            }
            match item {
                syn::Item::Mod(m) => self.child(m, &path, file, test, dir, file_path)?,
                syn::Item::Use(u) => {
                    let public = !matches!(u.vis, syn::Visibility::Inherited);
                    let mut flat = Vec::new();
                    flatten_use(&u.tree, Vec::new(), &mut flat);
                    let m = self.modules.entry(path.clone()).or_default();
                    for (binding, target) in flat {
                        match binding {
                            Some(name) if public => {
                                m.reexports.insert(name, target.clone());
                            }
                            None if public => m.globs.push(target.clone()),
                            Some(name) => {
                                m.bindings.insert(name, target.clone());
                            }
                            None => {}
                        }
                        if !(test || (public && facade)) {
                            m.uses.push(target);
                        }
                    }
                }
                other => {
                    let m = self.modules.entry(path.clone()).or_default();
                    if let Some(name) = item_name(other) {
                        m.items.insert(name);
                    }
                    if !test {
                        let mut v = PathCollector::default();
                        v.visit_item(other);
                        m.uses.extend(v.paths);
                    }
                }
            }
        }
        Ok(())
    }

    fn child(
        &mut self,
        m: &syn::ItemMod,
        parent: &[String],
        file: usize,
        test: bool,
        dir: &Path,
        file_path: &Path,
    ) -> Result<(), String> {
        let name = m.ident.to_string();
        let mut path = parent.to_vec();
        path.push(name.clone());
        self.modules
            .entry(parent.to_vec())
            .or_default()
            .children
            .insert(name.clone());
        let test = test || is_test(&m.attrs);
        if let Some((_, items)) = &m.content {
            return self.items(items, path, file, test, &dir.join(&name), file_path, false);
        }
        let (child_file, mod_rs) = match path_attr(&m.attrs) {
            Some(p) => {
                let base = file_path.parent().unwrap_or(Path::new(""));
                (base.join(p), true)
            }
            None => {
                let flat = dir.join(format!("{name}.rs"));
                if flat.is_file() {
                    (flat, false)
                } else {
                    (dir.join(&name).join("mod.rs"), true)
                }
            }
        };
        self.file(&child_file, path, test, mod_rs)
    }

    /// The module a path used in module `at` ends in (following re-exports).
    pub fn resolve(&self, at: &[String], used: &[String], depth: usize) -> Option<Vec<String>> {
        if depth > 8 {
            return None;
        }
        let mut cur: Vec<String> = at.to_vec();
        let mut rest = used;
        match used.first().map(String::as_str) {
            Some("crate") => {
                cur.clear();
                rest = &used[1..];
            }
            Some("self") => rest = &used[1..],
            Some("super") => {
                while rest.first().is_some_and(|s| s == "super") {
                    cur.pop()?;
                    rest = &rest[1..];
                }
            }
            Some(first)
                if self
                    .modules
                    .get(at)
                    .is_some_and(|m| m.children.contains(first)) => {}
            Some(first) => {
                let bound = self.modules.get(at)?.bindings.get(first)?;
                if bound.len() < 2 {
                    return None;
                }
                let mut p = bound.clone();
                p.extend(used[1..].iter().cloned());
                return self.resolve(at, &p, depth + 1);
            }
            _ => return None,
        }
        self.walk(cur, rest, depth)
    }

    fn walk(&self, mut cur: Vec<String>, rest: &[String], depth: usize) -> Option<Vec<String>> {
        for (i, seg) in rest.iter().enumerate() {
            let m = self.modules.get(&cur)?;
            if m.children.contains(seg) {
                cur.push(seg.clone());
                continue;
            }
            if m.items.contains(seg) {
                return Some(cur);
            }
            if let Some(target) = m.reexports.get(seg) {
                let mut p = target.clone();
                p.extend(rest[i + 1..].iter().cloned());
                return self.resolve(&cur, &p, depth + 1).or(Some(cur));
            }
            for g in &m.globs {
                let mut p = g.clone();
                p.extend(rest[i..].iter().cloned());
                if let Some(found) = self.resolve(&cur, &p, depth + 1)
                    && self.modules[&found].items.contains(seg)
                {
                    return Some(found);
                }
            }
            return Some(cur);
        }
        Some(cur)
    }
}
