//! Finding the service binaries: next to the running `spacepose`, else on `PATH`.

use std::path::{Path, PathBuf};

/// Where binaries are looked up.
#[derive(Debug, Clone, Default)]
pub struct BinarySearch {
    /// Directory of the running `spacepose` executable (searched first).
    pub exe_dir: Option<PathBuf>,
    /// The `PATH` directories.
    pub path: Vec<PathBuf>,
    /// Directory relative `binary = "..."` entries are resolved against.
    pub base_dir: PathBuf,
}

impl BinarySearch {
    /// The search of this process: its own directory, then `PATH`;
    /// relative entries against `base_dir` (the descriptor's directory).
    pub fn from_env(base_dir: &Path) -> Self {
        let exe_dir = std::env::current_exe()
            .ok()
            .and_then(|p| p.parent().map(Path::to_path_buf));
        let path = std::env::var_os("PATH")
            .map(|p| std::env::split_paths(&p).collect())
            .unwrap_or_default();
        Self {
            exe_dir,
            path,
            base_dir: base_dir.to_path_buf(),
        }
    }

    /// Resolves an explicit `binary` entry, or finds `name`.
    pub fn resolve(&self, explicit: Option<&Path>, name: &str) -> Result<PathBuf, String> {
        if let Some(p) = explicit {
            let p = if p.is_absolute() {
                p.to_path_buf()
            } else {
                self.base_dir.join(p)
            };
            return if is_executable(&p) {
                Ok(p)
            } else {
                Err(format!(
                    "binary {} does not exist or is not executable",
                    p.display()
                ))
            };
        }
        let candidates = self.exe_dir.iter().chain(self.path.iter());
        for dir in candidates {
            let p = dir.join(name);
            if is_executable(&p) {
                return Ok(p);
            }
        }
        let exe_dir = self
            .exe_dir
            .as_ref()
            .map_or_else(|| "?".to_string(), |d| d.display().to_string());
        Err(format!(
            "binary {name} not found next to spacepose ({exe_dir}) nor on PATH \
             (build it: cargo build --release -p {name})"
        ))
    }
}

/// True for an existing regular file with an execute bit.
pub fn is_executable(path: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    std::fs::metadata(path).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_next_to_the_executable_then_on_path() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a");
        let b = dir.path().join("b");
        std::fs::create_dir_all(&a).unwrap();
        std::fs::create_dir_all(&b).unwrap();
        let make = |p: &Path| {
            std::fs::write(p, "#!/bin/sh\n").unwrap();
            std::fs::set_permissions(p, std::fs::Permissions::from_mode(0o755)).unwrap();
        };
        make(&b.join("spacepose-x"));
        make(&a.join("spacepose-y"));
        std::fs::write(a.join("spacepose-z"), "not executable").unwrap();
        let s = BinarySearch {
            exe_dir: Some(a.clone()),
            path: vec![b.clone()],
            base_dir: dir.path().to_path_buf(),
        };
        assert_eq!(
            s.resolve(None, "spacepose-x").unwrap(),
            b.join("spacepose-x")
        );
        assert_eq!(
            s.resolve(None, "spacepose-y").unwrap(),
            a.join("spacepose-y")
        );
        let e = s.resolve(None, "spacepose-z").unwrap_err();
        assert!(e.contains("cargo build --release -p spacepose-z"), "{e}");
        assert_eq!(
            s.resolve(Some(Path::new("a/spacepose-y")), "ignored")
                .unwrap(),
            a.join("spacepose-y")
        );
        assert!(s.resolve(Some(Path::new("nope")), "x").is_err());
    }
}
