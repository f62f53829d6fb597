//! The Gaussian prior on a scan's start pose `T^s` that the free-start
//! CT-NDT ([`super::register_ct_ndt_free_start`]) optimises against.

use crate::error::RegistrationError;
use crate::source::check_pose;
use nalgebra::Matrix6;
use spacepose_geometry::Pose;

/// A Gaussian prior on the start pose `T^s = t_target_sensor` of a scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StartPrior {
    /// Mean of `T^s`.
    pub t_target_sensor: Pose,
    /// Information (inverse covariance) of a left perturbation
    /// `δ = [rot; trans]` of the mean (seed 000 Eq. 5); symmetric positive
    /// semi-definite, in the units of the NDT information (Eq. 7).
    pub information: Matrix6<f64>,
}

impl StartPrior {
    /// Rejects a non-finite mean or information, or a negative diagonal.
    pub fn validate(&self) -> Result<(), RegistrationError> {
        check_pose("start prior", &self.t_target_sensor)?;
        let ok = self.information.iter().all(|v| v.is_finite())
            && self.information.diagonal().iter().all(|&d| d >= 0.0);
        if ok {
            Ok(())
        } else {
            Err(RegistrationError::param(
                "start_prior.information",
                "need a finite matrix with a non-negative diagonal",
            ))
        }
    }
}
