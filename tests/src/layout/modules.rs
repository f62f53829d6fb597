//! The module tree of one crate target and the imports between its files.
//!
//! A file imports another when one of its non-test items names, through
//! `crate::`, `super::`, `self::` or a child module, an item that the other
//! file defines. Re-exports are followed to the defining file, so
//! `crate::Thing` counts as an import of the file where `Thing` lives, not
//! of `lib.rs`. A facade's own `pub use` lines (in `lib.rs`, `main.rs`,
//! `mod.rs`) are not imports. Test modules (`#[cfg(test)]`) are left out.

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
struct Module {
    file: usize,
    children: BTreeSet<String>,
    items: BTreeSet<String>,
    /// `pub use` bindings: name → path (as written).
    reexports: BTreeMap<String, Vec<String>>,
    globs: Vec<Vec<String>>,
    /// Paths named by the module's own (non-test) code.
    uses: Vec<Vec<String>>,
}

/// The files of one crate target and the imports between them.
#[derive(Debug, Clone)]
pub struct CrateModules {
    /// Files, the root first.
    pub files: Vec<ModuleFile>,
    /// Imports `(from, to)` between files (indices into `files`).
    pub imports: BTreeSet<(usize, usize)>,
}

impl CrateModules {
    /// Reads the crate whose root is `root` (`src/lib.rs`, `src/main.rs`).
    pub fn load(root: &Path) -> Result<CrateModules, String> {
        let mut w = Walker::default();
        w.file(root, Vec::new(), false, true)?;
        let mut imports = BTreeSet::new();
        for (path, m) in &w.modules {
            if w.files[m.file].test {
                continue;
            }
            for used in &m.uses {
                if let Some(target) = w.resolve(path, used, 0) {
                    let to = w.modules[&target].file;
                    if to != m.file && !w.files[to].test {
                        imports.insert((m.file, to));
                    }
                }
            }
        }
        Ok(CrateModules {
            files: w.files,
            imports,
        })
    }

    /// Production files (not test-only).
    pub fn production_files(&self) -> impl Iterator<Item = &Path> {
        self.files
            .iter()
            .filter(|f| !f.test)
            .map(|f| f.file.as_path())
    }
}

/// The import circles of a crate: each strongly connected set of two or
/// more files, as file paths.
pub fn circles(c: &CrateModules) -> Vec<Vec<PathBuf>> {
    let n = c.files.len();
    let mut adj = vec![Vec::new(); n];
    for &(a, b) in &c.imports {
        adj[a].push(b);
    }
    tarjan(&adj)
        .into_iter()
        .filter(|scc| scc.len() > 1)
        .map(|scc| {
            let mut files: Vec<PathBuf> = scc.iter().map(|&i| c.files[i].file.clone()).collect();
            files.sort();
            files
        })
        .collect()
}

/// Strongly connected components (Tarjan, iterative enough for a crate).
fn tarjan(adj: &[Vec<usize>]) -> Vec<Vec<usize>> {
    struct S<'a> {
        adj: &'a [Vec<usize>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit(s: &mut S<'_>, v: usize) {
        s.index[v] = Some(s.next);
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on[v] = true;
        for &w in &s.adj[v] {
            match s.index[w] {
                None => {
                    visit(s, w);
                    s.low[v] = s.low[v].min(s.low[w]);
                }
                Some(iw) if s.on[w] => s.low[v] = s.low[v].min(iw),
                Some(_) => {}
            }
        }
        if Some(s.low[v]) == s.index[v] {
            let mut scc = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on[w] = false;
                scc.push(w);
                if w == v {
                    break;
                }
            }
            s.out.push(scc);
        }
    }
    let n = adj.len();
    let mut s = S {
        adj,
        index: vec![None; n],
        low: vec![0; n],
        on: vec![false; n],
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(&mut s, v);
        }
    }
    s.out
}

#[derive(Default)]
struct Walker {
    files: Vec<ModuleFile>,
    modules: BTreeMap<Vec<String>, Module>,
}

impl Walker {
    /// Reads `file` as module `path`; `mod_rs`: its children live in its
    /// own directory (lib.rs, main.rs, mod.rs, or a `#[path]` file).
    fn file(
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
                            _ => {}
                        }
                        if !(public && facade) && !test {
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
    fn resolve(&self, at: &[String], used: &[String], depth: usize) -> Option<Vec<String>> {
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

/// `(binding, path)` of every leaf of a use tree; `None` for a glob.
fn flatten_use(
    tree: &syn::UseTree,
    prefix: Vec<String>,
    out: &mut Vec<(Option<String>, Vec<String>)>,
) {
    match tree {
        syn::UseTree::Path(p) => {
            let mut next = prefix;
            next.push(p.ident.to_string());
            flatten_use(&p.tree, next, out);
        }
        syn::UseTree::Name(n) => {
            let name = n.ident.to_string();
            let mut path = prefix;
            if name != "self" {
                path.push(name.clone());
            }
            let binding = path.last().cloned();
            out.push((binding, path));
        }
        syn::UseTree::Rename(r) => {
            let mut path = prefix;
            path.push(r.ident.to_string());
            out.push((Some(r.rename.to_string()), path));
        }
        syn::UseTree::Glob(_) => out.push((None, prefix)),
        syn::UseTree::Group(g) => {
            for t in &g.items {
                flatten_use(t, prefix.clone(), out);
            }
        }
    }
}

#[derive(Default)]
struct PathCollector {
    paths: Vec<Vec<String>>,
}

impl<'ast> Visit<'ast> for PathCollector {
    fn visit_path(&mut self, p: &'ast syn::Path) {
        if let Some(first) = p.segments.first() {
            let f = first.ident.to_string();
            if f == "crate" || f == "super" || f == "self" || p.segments.len() > 1 {
                self.paths
                    .push(p.segments.iter().map(|s| s.ident.to_string()).collect());
            }
        }
        syn::visit::visit_path(self, p);
    }

    fn visit_item_mod(&mut self, _: &'ast syn::ItemMod) {}

    fn visit_attribute(&mut self, _: &'ast syn::Attribute) {}

    fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
        if !is_test(&f.attrs) {
            syn::visit::visit_impl_item_fn(self, f);
        }
    }
}

fn attrs_of(item: &syn::Item) -> &[syn::Attribute] {
    match item {
        syn::Item::Const(i) => &i.attrs,
        syn::Item::Enum(i) => &i.attrs,
        syn::Item::Fn(i) => &i.attrs,
        syn::Item::Impl(i) => &i.attrs,
        syn::Item::Macro(i) => &i.attrs,
        syn::Item::Mod(i) => &i.attrs,
        syn::Item::Static(i) => &i.attrs,
        syn::Item::Struct(i) => &i.attrs,
        syn::Item::Trait(i) => &i.attrs,
        syn::Item::Type(i) => &i.attrs,
        syn::Item::Union(i) => &i.attrs,
        syn::Item::Use(i) => &i.attrs,
        _ => &[],
    }
}

fn item_name(item: &syn::Item) -> Option<String> {
    Some(match item {
        syn::Item::Const(i) => i.ident.to_string(),
        syn::Item::Enum(i) => i.ident.to_string(),
        syn::Item::Fn(i) => i.sig.ident.to_string(),
        syn::Item::Static(i) => i.ident.to_string(),
        syn::Item::Struct(i) => i.ident.to_string(),
        syn::Item::Trait(i) => i.ident.to_string(),
        syn::Item::Type(i) => i.ident.to_string(),
        syn::Item::Union(i) => i.ident.to_string(),
        syn::Item::Macro(i) => i.ident.as_ref()?.to_string(),
        _ => return None,
    })
}

/// `#[cfg(test)]`, or any `cfg` that names `test`.
fn is_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg")
            && a.meta.require_list().is_ok_and(|l| {
                l.tokens
                    .to_string()
                    .split(|c: char| !c.is_alphanumeric() && c != '_')
                    .any(|w| w == "test")
            })
    })
}

fn path_attr(attrs: &[syn::Attribute]) -> Option<String> {
    attrs.iter().find_map(|a| {
        let nv = a.meta.require_name_value().ok()?;
        if !a.path().is_ident("path") {
            return None;
        }
        match &nv.value {
            syn::Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(s),
                ..
            }) => Some(s.value()),
            _ => None,
        }
    })
}
