//! ICP refinement of a template solution (seed 002 §4.2, §4.5): staged
//! point-to-point ICP from the template pose, then f_CONV at convergence.

use crate::config::TemplateMatchingConfig;
use spacepose_geometry::{Point, Pose};
use spacepose_registration::{IcpModel, IcpParams, RegistrationError, register_icp};

/// A refined pose with the figures the failure check needs.
#[derive(Debug, Clone, PartialEq)]
pub struct Refined {
    /// The refined pose (target body → sensor).
    pub t_sensor_target: Pose,
    /// f_CONV (m²).
    pub f_conv_m2: f64,
    /// Iterations over all stages.
    pub iterations: usize,
    /// The final stage converged.
    pub converged: bool,
    /// Inlier fraction of the final stage.
    pub inlier_fraction: f64,
}

/// Runs the wide stages of `config.icp_stages_m`, then `config.icp`, from
/// `t_sensor_target`; f_CONV is that of the final stage.
pub fn refine(
    model: &IcpModel,
    cloud: &[Point],
    t_sensor_target: &Pose,
    config: &TemplateMatchingConfig,
) -> Result<Refined, RegistrationError> {
    let mut t_target_sensor = t_sensor_target.inverse();
    let mut iterations = 0;
    for &d in &config.icp_stages_m {
        let params = IcpParams {
            max_distance_m: d,
            max_iterations: config.icp_stage_iterations,
            termination_increment: config.icp.termination_increment.max(1e-4),
            ..config.icp
        };
        let r = register_icp(model, cloud, &t_target_sensor, &params)?;
        iterations += r.iterations;
        t_target_sensor = r.t_target_sensor;
    }
    let r = register_icp(model, cloud, &t_target_sensor, &config.icp)?;
    Ok(Refined {
        t_sensor_target: r.t_sensor_target(),
        f_conv_m2: r.f_conv_m2.unwrap_or(f64::INFINITY),
        iterations: iterations + r.iterations,
        converged: r.converged,
        inlier_fraction: r.inlier_fraction(),
    })
}
