//! The module tree of one crate target and the imports between its files.
//!
//! A file imports another when one of its non-test items names, through
//! `crate::`, `super::`, `self::` or a child module, an item that the other
//! file defines. Re-exports are followed to the defining file, so
//! `crate::Thing` counts as an import of the file where `Thing` lives, not
//! of `lib.rs`. A facade's own `pub use` lines (in `lib.rs`, `main.rs`,
//! `mod.rs`) are not imports. Test modules (`#[cfg(test)]`) are left out.

mod syntax;
mod walker;

pub use walker::ModuleFile;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use walker::Walker;

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

#[cfg(test)]
#[path = "modules_tests.rs"]
mod tests;
