//! The error type of every fallible operation of this crate.

use std::path::PathBuf;

/// What can go wrong when building or loading a map, or registering a cloud.
///
/// Bad input is always reported through one of these values; no function of
/// this crate panics on input.
#[derive(Debug, thiserror::Error)]
pub enum RegistrationError {
    /// The source cloud handed to a registration has no points at all.
    #[error("the source cloud is empty")]
    EmptyCloud,

    /// Every point of the source cloud has a non-finite coordinate (or, for
    /// the continuous-time NDT, a non-finite timestamp). Individual
    /// non-finite points are otherwise skipped and counted in the result.
    #[error("all {count} points of the source cloud are non-finite")]
    AllPointsNonFinite {
        /// Number of points in the cloud.
        count: usize,
    },

    /// No point of the source cloud lies within the maximum correspondence
    /// distance of the map (or model) at the pose being evaluated: the cloud
    /// is entirely outside the map, or the initial guess is far off.
    #[error("no correspondences within {max_distance_m} m at iteration {iteration}")]
    NoCorrespondences {
        /// Gauss-Newton / ICP iteration at which it happened (0 = initial pose).
        iteration: usize,
        /// The maximum correspondence distance in use (m).
        max_distance_m: f64,
    },

    /// The normal equations are not positive definite (too few or
    /// degenerate correspondences, e.g. all on one line), or the solved
    /// increment is not finite.
    #[error("degenerate normal equations at iteration {iteration} ({inliers} inliers)")]
    DegenerateSystem {
        /// Iteration at which it happened (0 = first linearisation).
        iteration: usize,
        /// Number of correspondences that entered the system.
        inliers: usize,
    },

    /// The model cloud is empty, or has too few finite points to build a map
    /// or a kd-tree.
    #[error("invalid model: {0}")]
    InvalidModel(String),

    /// A parameter (or an initial pose, or a time interval) is NaN,
    /// infinite, non-positive or otherwise outside its domain.
    #[error("invalid parameter `{name}`: {reason}")]
    InvalidParameter {
        /// Name of the offending parameter.
        name: &'static str,
        /// Why it was rejected.
        reason: String,
    },

    /// Reading or writing a map file failed at the operating-system level.
    #[error("map file {path}: {source}")]
    MapIo {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },

    /// A map file does not start with the expected magic bytes: it is not a
    /// map file of this crate.
    #[error("map file {path}: bad magic, not a spacepose NDT map")]
    MapBadMagic {
        /// The file.
        path: PathBuf,
    },

    /// A map file was written by an incompatible version of the format.
    #[error("map file {path}: format version {found}, expected {expected}")]
    MapVersion {
        /// The file.
        path: PathBuf,
        /// Version found in the header.
        found: u32,
        /// Version this build reads and writes.
        expected: u32,
    },

    /// A map file is truncated, fails its checksum, cannot be decoded, or
    /// decodes to an inconsistent map.
    #[error("map file {path}: corrupt ({reason})")]
    MapCorrupt {
        /// The file.
        path: PathBuf,
        /// What was found wrong.
        reason: String,
    },
}

impl RegistrationError {
    /// Shorthand for [`RegistrationError::InvalidParameter`].
    pub(crate) fn param(name: &'static str, reason: impl Into<String>) -> Self {
        Self::InvalidParameter {
            name,
            reason: reason.into(),
        }
    }
}
