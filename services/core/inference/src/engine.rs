//! Choice of inference engine, and where the ONNX Runtime library is found.

use std::path::{Path, PathBuf};

use crate::error::InferenceError;

/// Environment variable naming the ONNX Runtime shared library (as ort uses it).
pub const ORT_DYLIB_ENV: &str = "ORT_DYLIB_PATH";

/// The training venv, relative to the workspace root, whose onnxruntime wheel
/// ships the library (`lib/python3.*/site-packages/onnxruntime/capi/`).
const TRAIN_VENV: &str = "tools/train/.venv";

/// Which engine runs the network.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Engine {
    /// tract-onnx, pure Rust, always available (the default).
    Tract,
    /// ONNX Runtime through `ort`, loaded at run time from `library`
    /// (`libonnxruntime.so.<version>`). Needs the crate feature `ort`;
    /// without it, loading fails with [`InferenceError::OrtNotCompiled`].
    Ort {
        /// Path of the ONNX Runtime shared library.
        library: PathBuf,
    },
}

impl Engine {
    /// Short name: `tract` or `ort`.
    pub fn name(&self) -> &'static str {
        match self {
            Engine::Tract => "tract",
            Engine::Ort { .. } => "ort",
        }
    }

    /// The ort engine with the library of [`find_ort_library`].
    pub fn ort_default() -> Result<Engine, InferenceError> {
        find_ort_library().map(|library| Engine::Ort { library })
    }

    /// Whether this build can run the engine (ort needs the `ort` feature).
    pub fn is_compiled(&self) -> bool {
        match self {
            Engine::Tract => true,
            Engine::Ort { .. } => cfg!(feature = "ort"),
        }
    }
}

/// Finds the ONNX Runtime library: `$ORT_DYLIB_PATH` when set (it must then
/// exist), else `libonnxruntime.so*` in the training venv's onnxruntime wheel,
/// looked up from the current directory and from the workspace root.
pub fn find_ort_library() -> Result<PathBuf, InferenceError> {
    if let Some(path) = std::env::var_os(ORT_DYLIB_ENV).filter(|p| !p.is_empty()) {
        let path = PathBuf::from(path);
        return if path.is_file() {
            Ok(path)
        } else {
            Err(InferenceError::OrtLibraryNotFound { path })
        };
    }
    let roots = [
        PathBuf::from("."),
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../.."),
    ];
    let mut searched = vec![format!("${ORT_DYLIB_ENV} (unset)")];
    for root in roots {
        let venv_lib = root.join(TRAIN_VENV).join("lib");
        searched.push(format!(
            "{}/python3.*/site-packages/onnxruntime/capi/libonnxruntime.so*",
            venv_lib.display()
        ));
        if let Some(found) = library_in_venv_lib(&venv_lib) {
            return Ok(found);
        }
    }
    Err(InferenceError::OrtLibraryNotFoundAnywhere {
        searched: searched.join(", "),
    })
}

/// `venv_lib/python3.*/site-packages/onnxruntime/capi/libonnxruntime.so*`,
/// the last by name when several match.
fn library_in_venv_lib(venv_lib: &Path) -> Option<PathBuf> {
    let pythons = std::fs::read_dir(venv_lib).ok()?;
    let mut found: Vec<PathBuf> = pythons
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with("python3"))
        .filter_map(|e| std::fs::read_dir(e.path().join("site-packages/onnxruntime/capi")).ok())
        .flat_map(|capi| capi.flatten())
        .filter(|e| is_runtime_library(&e.file_name().to_string_lossy()))
        .map(|e| e.path())
        .filter(|p| p.is_file())
        .collect();
    found.sort();
    found.pop()
}

/// `libonnxruntime.so` or `libonnxruntime.so.1.31.1`, not the providers' libraries.
fn is_runtime_library(name: &str) -> bool {
    name == "libonnxruntime.so" || name.starts_with("libonnxruntime.so.")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runtime_library_names() {
        assert!(is_runtime_library("libonnxruntime.so.1.31.1"));
        assert!(is_runtime_library("libonnxruntime.so"));
        assert!(!is_runtime_library("libonnxruntime_providers_shared.so"));
        assert!(!is_runtime_library(
            "onnxruntime_pybind11_state.cpython-311-x86_64-linux-gnu.so"
        ));
    }

    #[test]
    fn library_found_in_a_venv_layout() {
        let dir = tempfile::tempdir().unwrap();
        let lib = dir.path().join("lib");
        assert_eq!(library_in_venv_lib(&lib), None);
        let capi = lib.join("python3.11/site-packages/onnxruntime/capi");
        std::fs::create_dir_all(&capi).unwrap();
        std::fs::write(capi.join("libonnxruntime_providers_shared.so"), b"x").unwrap();
        assert_eq!(library_in_venv_lib(&lib), None);
        std::fs::write(capi.join("libonnxruntime.so.1.31.1"), b"x").unwrap();
        assert_eq!(
            library_in_venv_lib(&lib),
            Some(capi.join("libonnxruntime.so.1.31.1"))
        );
    }

    #[test]
    fn engine_names_and_availability() {
        assert_eq!(Engine::Tract.name(), "tract");
        let ort = Engine::Ort {
            library: PathBuf::from("x.so"),
        };
        assert_eq!(ort.name(), "ort");
        assert!(Engine::Tract.is_compiled());
        assert_eq!(ort.is_compiled(), cfg!(feature = "ort"));
    }
}
