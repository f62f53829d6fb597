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
    /// f_CONV (m²): the acceptance statistic, truncated at
    /// [`TemplateMatchingConfig::f_conv_cap_m`] per point when that is set.
    pub f_conv_m2: f64,
    /// The final ICP's mean squared distance over every point, uncapped
    /// (seed 002's f_CONV): what candidates are ranked by.
    pub msd_all_m2: f64,
    /// Iterations over all stages.
    pub iterations: usize,
    /// The final stage converged.
    pub converged: bool,
    /// Inlier fraction of the final stage.
    pub inlier_fraction: f64,
}

/// Runs the wide stages of `config.icp_stages_m` on `stage_model`, then
/// `config.icp` on `model`, from `t_sensor_target`; f_CONV is that of the
/// final stage.
pub fn refine(
    model: &IcpModel,
    stage_model: &IcpModel,
    cloud: &[Point],
    t_sensor_target: &Pose,
    config: &TemplateMatchingConfig,
) -> Result<Refined, RegistrationError> {
    refine_with_stages(
        model,
        stage_model,
        cloud,
        t_sensor_target,
        config,
        &config.icp_stages_m,
    )
}

/// [`refine`] with the wide stages `stages_m` instead of
/// `config.icp_stages_m` (e.g. only the narrowest after [`screen`]).
pub fn refine_with_stages(
    model: &IcpModel,
    stage_model: &IcpModel,
    cloud: &[Point],
    t_sensor_target: &Pose,
    config: &TemplateMatchingConfig,
    stages_m: &[f64],
) -> Result<Refined, RegistrationError> {
    let mut t_target_sensor = t_sensor_target.inverse();
    let mut iterations = 0;
    for &d in stages_m {
        let params = IcpParams {
            max_distance_m: d,
            max_iterations: config.icp_stage_iterations,
            termination_increment: config.icp.termination_increment.max(1e-4),
            far_lookup_from_m: config.far_lookup.as_ref().map(|f| f.from_m),
            ..config.icp
        };
        let r = register_icp(stage_model, cloud, &t_target_sensor, &params)?;
        iterations += r.iterations;
        t_target_sensor = r.t_target_sensor;
    }
    let r = register_icp(model, cloud, &t_target_sensor, &config.icp)?;
    let msd_all_m2 = r.f_conv_m2.unwrap_or(f64::INFINITY);
    let f_conv_m2 = if config.robust_f_conv {
        truncated_f_conv(
            r.inlier_fraction(),
            r.mean_squared_distance_m2,
            config.icp.max_distance_m,
        )
    } else if config.f_conv_cap_m > 0.0 {
        capped_f_conv(model, cloud, &r.t_target_sensor, config.f_conv_cap_m)
    } else {
        msd_all_m2
    };
    Ok(Refined {
        t_sensor_target: r.t_sensor_target(),
        f_conv_m2,
        msd_all_m2,
        iterations: iterations + r.iterations,
        converged: r.converged,
        inlier_fraction: r.inlier_fraction(),
    })
}

/// A short ICP from a template pose to rank candidates (see
/// [`TemplateMatchingConfig::screen_candidates`]): the wide stages and a
/// final one at `2 · icp.max_distance_m`, `screen_iterations` each, all on
/// `stage_model`. Returns the pose reached and its truncated f_CONV at that
/// final distance (lower is better).
pub fn screen(
    stage_model: &IcpModel,
    cloud: &[Point],
    t_sensor_target: &Pose,
    config: &TemplateMatchingConfig,
) -> Result<(Pose, f64), RegistrationError> {
    let final_m = 2.0 * config.icp.max_distance_m;
    let mut t_target_sensor = t_sensor_target.inverse();
    let mut last = None;
    for &d in config.icp_stages_m.iter().chain(std::iter::once(&final_m)) {
        let params = IcpParams {
            max_distance_m: d,
            max_iterations: config.screen_iterations,
            termination_increment: config.icp.termination_increment.max(1e-4),
            far_lookup_from_m: config.far_lookup.as_ref().map(|f| f.from_m),
            ..config.icp
        };
        let r = register_icp(stage_model, cloud, &t_target_sensor, &params)?;
        t_target_sensor = r.t_target_sensor;
        last = Some(r);
    }
    let score = last.map_or(f64::INFINITY, |r| {
        truncated_f_conv(r.inlier_fraction(), r.mean_squared_distance_m2, final_m)
    });
    Ok((t_target_sensor.inverse(), score))
}

/// f_CONV with every point's squared distance to the model capped at
/// `cap_m²` (see [`TemplateMatchingConfig::f_conv_cap_m`]): the mean over
/// the finite points of `min(d², cap²)` at `t_target_sensor`, with exact
/// nearest model points. Infinite for a cloud with no finite point.
pub fn capped_f_conv(model: &IcpModel, cloud: &[Point], t_target_sensor: &Pose, cap_m: f64) -> f64 {
    let cap2 = cap_m * cap_m;
    let (sum, n) = cloud
        .iter()
        .filter(|p| p.is_finite())
        .map(|p| {
            let q = t_target_sensor.transform(&p.position());
            model.squared_distance_m2(&q).min(cap2)
        })
        .fold((0.0, 0usize), |(s, n), d2| (s + d2, n + 1));
    if n == 0 {
        f64::INFINITY
    } else {
        sum / n as f64
    }
}

/// Truncated f_CONV (departure from seed 002 §4.5, see
/// [`TemplateMatchingConfig::robust_f_conv`]): the mean over every point of
/// `min(d², d_max²)`, from the inlier fraction `w` and the inlier mean
/// squared distance: `w · msd + (1 − w) · d_max²`.
pub fn truncated_f_conv(inlier_fraction: f64, inlier_msd_m2: f64, max_distance_m: f64) -> f64 {
    let w = inlier_fraction.clamp(0.0, 1.0);
    w * inlier_msd_m2 + (1.0 - w) * max_distance_m * max_distance_m
}

#[cfg(test)]
mod tests {
    use super::{capped_f_conv, truncated_f_conv};
    use nalgebra::Vector3;
    use spacepose_geometry::{Point, Pose};
    use spacepose_registration::IcpModel;

    #[test]
    fn capped_f_conv_caps_each_point() {
        // A plane of model points 5 cm apart at z = 0.
        let model: Vec<Vector3<f64>> = (0..41)
            .flat_map(|i| (0..41).map(move |j| Vector3::new(i as f64 * 0.05, j as f64 * 0.05, 0.0)))
            .collect();
        let model = IcpModel::new(&model).unwrap();
        let pose = Pose::identity();
        let on = |x: f64, z: f64| Point::new(x as f32, 1.0, z as f32, 0.0, 0.0);
        // Nine points 1 cm off the plane and a ghost 0.9 m off.
        let mut cloud: Vec<Point> = (0..9).map(|i| on(0.2 * i as f64, 0.01)).collect();
        cloud.push(on(1.0, 0.9));
        let capped = capped_f_conv(&model, &cloud, &pose, 0.2);
        let expected = (9.0 * 1e-4 + 0.04) / 10.0;
        assert!((capped - expected).abs() < 1e-9, "{capped} vs {expected}");
        let uncapped = capped_f_conv(&model, &cloud, &pose, 10.0);
        assert!(
            (uncapped - (9.0 * 1e-4 + 0.81) / 10.0).abs() < 1e-6,
            "{uncapped}"
        );
        let nan = [Point::new(f32::NAN, 0.0, 0.0, 0.0, 0.0)];
        assert!(capped_f_conv(&model, &nan, &pose, 0.2).is_infinite());
    }

    #[test]
    fn truncated_f_conv_caps_outliers_and_penalises_few_inliers() {
        // 2 % ghosts barely move a good fit...
        let good = truncated_f_conv(0.98, 1e-5, 0.1);
        assert!(good < 3e-4, "{good}");
        // ...while a wrong pose with half the points out stays high.
        let bad = truncated_f_conv(0.5, 2e-3, 0.1);
        assert!(bad > 10.0 * good, "{bad} vs {good}");
        assert!((truncated_f_conv(0.0, 0.0, 0.1) - 0.01).abs() < 1e-12);
    }
}
