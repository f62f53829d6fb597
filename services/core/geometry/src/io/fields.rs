//! What the PCD and PLY readers share: the [`Point`] field a file field
//! maps to, and the problems found in file content.

use std::path::Path;

use crate::error::GeometryError;
use crate::point::Point;

/// The [`Point`] field a file field maps to, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Role {
    X,
    Y,
    Z,
    T,
    Intensity,
}

impl Role {
    /// The role of field `name` when the time field is `time_name`.
    pub(super) fn of(name: &str, time_name: &str) -> Option<Self> {
        match name {
            "x" => Some(Self::X),
            "y" => Some(Self::Y),
            "z" => Some(Self::Z),
            "intensity" => Some(Self::Intensity),
            _ if name == time_name => Some(Self::T),
            _ => None,
        }
    }

    /// Stores `value` into the matching field of `p` (narrowing to `f32`
    /// for everything but `t`).
    #[inline]
    pub(super) fn set(self, p: &mut Point, value: f64) {
        match self {
            Self::X => p.x = value as f32,
            Self::Y => p.y = value as f32,
            Self::Z => p.z = value as f32,
            Self::T => p.t = value,
            Self::Intensity => p.intensity = value as f32,
        }
    }
}

/// A problem found while decoding file content, before the path is attached.
#[derive(Debug)]
pub(super) enum Issue {
    Malformed(String),
    Unsupported(String),
}

impl Issue {
    pub(super) fn at(self, path: &Path, format: &'static str) -> GeometryError {
        let path = path.to_path_buf();
        match self {
            Self::Malformed(message) => GeometryError::Malformed {
                path,
                format,
                message,
            },
            Self::Unsupported(message) => GeometryError::Unsupported {
                path,
                format,
                message,
            },
        }
    }
}

pub(super) fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> GeometryError + '_ {
    move |source| GeometryError::Io {
        path: path.to_path_buf(),
        source,
    }
}
