//! The data side of seed 004's CNN pose acquisition: depth-image
//! preprocessing (§III.A), attitude classes with symmetry reduction
//! (§III.C.1, §III.C.4), soft labels `L_sym` (Eq. 15), decoding `Γ_sym`
//! (Algorithm 1), and the synthetic dataset generator (§IV.B) with its
//! `.npy` writer, and the estimator ([`CnnEstimator`]: network, decoding,
//! NDT refinement §III.E and the f_CONV check). A library only: no bus.
//!
//! ```no_run
//! # fn demo(cloud: &[spacepose_geometry::Point]) -> Result<(), spacepose_cnn::CnnError> {
//! use spacepose_cnn::{ClassTable, PreprocessConfig, decode, preprocess, soft_labels};
//! let deos = spacepose_model::Target::builtin("deos").expect("built-in");
//! let image = preprocess(cloud, &PreprocessConfig::for_target(&deos, 64)?)?;
//! let classes = ClassTable::for_target(&deos, 20.0)?;   // m = 618
//! # let probs = soft_labels(&classes, &nalgebra::Rotation3::identity());
//! let r_sensor_target = decode(&classes, &probs, 50f64.to_radians())?;
//! # Ok(()) }
//! ```
#![forbid(unsafe_code)]

pub mod classes;
pub mod dataset;
pub mod decode;
pub mod domain;
pub mod error;
pub mod estimator;
pub mod labels;
pub mod model_meta;
pub mod npy;
pub mod preprocess;
pub mod refinement;
pub mod twins;

pub use classes::{ClassTable, DEFAULT_ROLL_STEP_DEG};
pub use dataset::{
    DEFAULT_MIN_POINTS, DatasetConfig, DatasetStats, GeneratedFrame, Generator, Sample,
};
pub use decode::{DEFAULT_DELTA_BETA_DEG, decode};
pub use error::CnnError;
pub use estimator::{CnnEstimate, CnnEstimator, EstimatorConfig, Timings};
pub use labels::soft_labels;
pub use preprocess::{DEFAULT_IMAGE_SIZE, DepthImage, PreprocessConfig, preprocess, roi_side_for};
pub use refinement::{RefinementConfig, Refiner};
pub use twins::{TwinCheckConfig, TwinOutcome};
