//! Errors of pose acquisition.

use spacepose_geometry::GeometryError;
use spacepose_lidar_sim::SimError;
use spacepose_registration::RegistrationError;
use thiserror::Error;

/// Everything that can go wrong when building a matcher or acquiring a pose.
#[derive(Debug, Error)]
pub enum AcquisitionError {
    /// The cloud has fewer finite points than template matching needs
    /// (sparse frame, all-NaN frame): a failure, never a pose.
    #[error("too few points to acquire: {valid} finite of {total}, at least {required} needed")]
    TooFewPoints {
        /// Finite points in the cloud.
        valid: usize,
        /// Points in the cloud, finite or not.
        total: usize,
        /// Minimum required ([`crate::TemplateMatchingConfig::min_points`]).
        required: usize,
    },
    /// A configuration value is out of its domain.
    #[error("invalid template-matching configuration: {field} = {value}: {reason}")]
    InvalidConfig {
        /// Name of the field.
        field: &'static str,
        /// Offending value (as f64).
        value: f64,
        /// What is expected.
        reason: &'static str,
    },
    /// The sensor configuration or the target's materials were refused.
    #[error("sensor or target refused: {0}")]
    Sensor(#[from] SimError),
    /// Building the ICP model or every ICP refinement failed.
    #[error("ICP refinement: {0}")]
    Registration(#[from] RegistrationError),
    /// Centroid computation failed.
    #[error("centroid: {0}")]
    Geometry(#[from] GeometryError),
    /// No template could be correlated (every template empty, or every one
    /// rejected by the D_BOR test of the fast variant).
    #[error("no template evaluated ({generated} generated, {rejected} rejected by D_BOR)")]
    NoTemplate {
        /// Templates rendered.
        generated: usize,
        /// Templates rejected by Eq. (3).
        rejected: usize,
    },
}
