//! Template matching (seed 002 §2, `spacepose-acquisition`) as a
//! [`PoseAcquirer`].

use crate::error::InitError;
use crate::method::{MethodOutput, PoseAcquirer};
use spacepose_acquisition::{TemplateMatcher, TemplateMatchingConfig};
use spacepose_geometry::Point;
use spacepose_lidar_sim::SensorConfig;
use spacepose_messages::AcquisitionMethod;
use spacepose_model::Target;
use std::sync::Arc;

/// The template matcher, built once (grid, renderers, ICP model).
pub struct TemplateMatching {
    matcher: TemplateMatcher,
}

impl TemplateMatching {
    /// Builds the matcher for `target` seen by `sensor`.
    pub fn new(
        target: Arc<Target>,
        sensor: SensorConfig,
        config: TemplateMatchingConfig,
    ) -> Result<Self, InitError> {
        let matcher =
            TemplateMatcher::new(target, sensor, config).map_err(|e| InitError::Build {
                method: AcquisitionMethod::TemplateMatching.as_str(),
                reason: e.to_string(),
            })?;
        Ok(Self { matcher })
    }
}

impl PoseAcquirer for TemplateMatching {
    fn method(&self) -> AcquisitionMethod {
        AcquisitionMethod::TemplateMatching
    }

    fn acquire(&self, cloud: &[Point]) -> Result<MethodOutput, InitError> {
        let o = self.matcher.acquire(cloud).map_err(|e| InitError::Method {
            method: AcquisitionMethod::TemplateMatching.as_str(),
            reason: e.to_string(),
        })?;
        Ok(MethodOutput {
            t_sensor_target: o.t_sensor_target,
            f_conv_m2: o.f_conv_m2,
            accepted: o.accepted,
            detail: format!(
                "{} points, {} templates evaluated, matching {:.0} ms, ICP {:.0} ms ({} \
                 iterations), unexplained {:.2}{}",
                o.points_used,
                o.templates_evaluated,
                o.matching_ms,
                o.refinement_ms,
                o.icp_iterations,
                o.unexplained_fraction,
                if o.twin_ambiguous {
                    ", rejected: another hypothesis (a twin) fits as well"
                } else {
                    ""
                }
            ),
        })
    }
}
