//! What an acquisition returns.

use serde::Serialize;
use spacepose_geometry::{Euler321, Pose};

/// The result of one acquisition: the refined pose, the template solution
/// before refinement, the f_CONV check (seed 002 §4.5) and the costs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AcquisitionOutcome {
    /// The pose after ICP refinement (target body → sensor). The template
    /// solution when every refinement failed.
    pub t_sensor_target: Pose,
    /// The template-matching solution before ICP: the grid attitude with
    /// the smallest C, and the position of the target origin implied by
    /// the centroid alignment (sensor centroid + sensor centroid − template
    /// centroid).
    pub t_sensor_target_coarse: Pose,
    /// The grid triplet of the template solution.
    pub euler_coarse: Euler321,
    /// Position estimate of seed 002 §2.1: the (trimmed) centroid of the cloud.
    pub centroid_m: [f64; 3],
    /// C of Eq. (1) of the chosen template (m²).
    pub correlation_m2: f64,
    /// f_CONV: mean squared distance of every point to the model at ICP
    /// convergence (m²); infinite when every refinement failed.
    pub f_conv_m2: f64,
    /// Unexplained fraction of the solution: the share of the template
    /// rendered at the refined pose that no sensed point explains (see
    /// [`crate::visibility`]); 1 when every refinement failed.
    pub unexplained_fraction: f64,
    /// `f_conv_m2 <= f_max_m2`, `unexplained_fraction <= u_max` and no
    /// twin ambiguity: the solution can initialise tracking.
    pub accepted: bool,
    /// Templates rendered (both passes of coarse-to-fine count).
    pub templates_generated: usize,
    /// Templates whose C was evaluated.
    pub templates_evaluated: usize,
    /// Templates skipped by the D_BOR test of Eq. (3) (fast variant).
    pub templates_rejected: usize,
    /// Finite points of the cloud.
    pub points_used: usize,
    /// Total wall time of [`crate::TemplateMatcher::acquire`] (ms).
    pub time_ms: f64,
    /// Of which template matching (ms).
    pub matching_ms: f64,
    /// Of which ICP refinement (ms).
    pub refinement_ms: f64,
    /// Candidates refined by ICP.
    pub candidates_refined: usize,
    /// Candidates screened by a short ICP before the refinement (0 when
    /// screening is off).
    pub candidates_screened: usize,
    /// Rank (0 = best) of the candidate whose refinement won: by C, or
    /// with screening by the screening score.
    pub chosen_rank: usize,
    /// ICP iterations of the winning refinement (all stages).
    pub icp_iterations: usize,
    /// The final ICP stage met its termination test.
    pub icp_converged: bool,
    /// Fraction of the points within the final correspondence distance.
    pub icp_inlier_fraction: f64,
    /// Why refinement failed for the winning candidate, if it did.
    pub refinement_error: Option<String>,
    /// A near-symmetric twin of the solution fits the frame about as well
    /// (see the matcher's twin check): the solution is not accepted.
    pub twin_ambiguous: bool,
}
