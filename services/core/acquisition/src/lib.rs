//! Pose acquisition without training data for spacepose: the on-line
//! template matching of seed 002 §2 (Fig. 2), its fast variant (§2.2,
//! Eq. 2-3), ICP refinement of the template solution and the autonomous
//! failure check on f_CONV (§4.5, Fig. 10). A library only: no bus.
//!
//! Build a [`TemplateMatcher`] once per target and sensor (grid, template
//! renderers, ICP model), then call [`TemplateMatcher::acquire`] on a
//! frame. An outcome with `accepted == false` means: wait and try again on
//! a later frame.
#![forbid(unsafe_code)]

pub mod config;
pub mod correlation;
pub mod error;
pub mod grid;
pub mod matcher;
pub mod outcome;
pub mod refine;
pub mod slide_search;
pub mod template;
pub mod translation_vote;
pub mod visibility;

pub use config::{CoarseToFine, FarLevel, FarLookup, TemplateMatchingConfig, Threads};
pub use correlation::{Centering, Correlator, d_bor, d_bor_passes};
pub use error::AcquisitionError;
pub use grid::euler_grid;
pub use matcher::TemplateMatcher;
pub use outcome::AcquisitionOutcome;
pub use refine::{Refined, refine, refine_with_stages, screen};
pub use spacepose_registration::IcpParams;
pub use template::{TemplateRenderer, template_directions};
pub use translation_vote::{VoteScratch, vote_translation};
pub use visibility::SensedTree;
