//! Validation of [`TemplateMatchingConfig`]: every field checked for NaN
//! and its domain, in declaration order of the checks.

use super::TemplateMatchingConfig;
use crate::error::AcquisitionError;

fn bad(field: &'static str, value: f64, reason: &'static str) -> AcquisitionError {
    AcquisitionError::InvalidConfig {
        field,
        value,
        reason,
    }
}

impl TemplateMatchingConfig {
    /// Rejects NaN and out-of-domain values.
    pub fn validate(&self) -> Result<(), AcquisitionError> {
        self.validate_matching()?;
        self.validate_refinement()?;
        self.validate_models()
    }

    /// The grid, the correlation and the acceptance figures.
    fn validate_matching(&self) -> Result<(), AcquisitionError> {
        crate::grid::euler_grid(self.delta_deg)?;
        if !(self.tau.is_finite() && self.tau > 0.0) {
            return Err(bad("tau", self.tau, "must be finite and > 0"));
        }
        if !(0.0..0.5).contains(&self.trim) {
            return Err(bad("trim", self.trim, "must be in [0, 0.5["));
        }
        if !(self.f_max_m2.is_finite() && self.f_max_m2 > 0.0) {
            return Err(bad("f_max_m2", self.f_max_m2, "must be finite and > 0"));
        }
        if !(self.unexplained_spacings.is_finite() && self.unexplained_spacings > 0.0) {
            return Err(bad(
                "unexplained_spacings",
                self.unexplained_spacings,
                "must be finite and > 0",
            ));
        }
        if !(self.unexplained_weight_m2.is_finite() && self.unexplained_weight_m2 >= 0.0) {
            return Err(bad(
                "unexplained_weight_m2",
                self.unexplained_weight_m2,
                "must be finite and >= 0",
            ));
        }
        if !(self.translation_vote_bin_m.is_finite() && self.translation_vote_bin_m >= 0.0) {
            return Err(bad(
                "translation_vote_bin_m",
                self.translation_vote_bin_m,
                "must be finite and >= 0",
            ));
        }
        if !(self.f_conv_cap_m.is_finite() && self.f_conv_cap_m >= 0.0) {
            return Err(bad(
                "f_conv_cap_m",
                self.f_conv_cap_m,
                "must be finite and >= 0",
            ));
        }
        if !(self.slide_reach_m.is_finite() && self.slide_reach_m >= 0.0) {
            return Err(bad(
                "slide_reach_m",
                self.slide_reach_m,
                "must be finite and >= 0",
            ));
        }
        if !(self.twin_ambiguity == 0.0 || self.twin_ambiguity >= 1.0)
            || !self.twin_ambiguity.is_finite()
        {
            return Err(bad(
                "twin_ambiguity",
                self.twin_ambiguity,
                "must be 0 (off) or a finite factor >= 1",
            ));
        }
        if !(self.u_max >= 0.0 && self.u_max <= 1.0) {
            return Err(bad("u_max", self.u_max, "must be in [0, 1]"));
        }
        Ok(())
    }

    /// The ICP stages, the templates, the candidates and the cloud size.
    fn validate_refinement(&self) -> Result<(), AcquisitionError> {
        self.icp.validate()?;
        if let Some(&d) = self
            .icp_stages_m
            .iter()
            .find(|d| !(d.is_finite() && **d > 0.0))
        {
            return Err(bad("icp_stages_m", d, "must be finite and > 0"));
        }
        if self.icp_stage_iterations == 0 {
            return Err(bad("icp_stage_iterations", 0.0, "must be >= 1"));
        }
        if self.template_stride == 0 {
            return Err(bad("template_stride", 0.0, "must be >= 1"));
        }
        if let Some(c) = self.coarse_to_fine
            && (c.stride == 0 || c.keep == 0)
        {
            return Err(bad("coarse_to_fine", 0.0, "stride and keep must be >= 1"));
        }
        if self.screen_iterations == 0 {
            return Err(bad("screen_iterations", 0.0, "must be >= 1"));
        }
        if self.icp_candidates == 0 {
            return Err(bad("icp_candidates", 0.0, "must be >= 1"));
        }
        if !(self.candidate_separation_deg.is_finite() && self.candidate_separation_deg >= 0.0) {
            return Err(bad(
                "candidate_separation_deg",
                self.candidate_separation_deg,
                "must be finite and >= 0",
            ));
        }
        if self.min_points < 3 {
            return Err(bad("min_points", self.min_points as f64, "must be >= 3"));
        }
        Ok(())
    }

    /// The model clouds and the far lookup.
    fn validate_models(&self) -> Result<(), AcquisitionError> {
        if !(self.model_spacing_m.is_finite() && self.model_spacing_m > 0.0) {
            return Err(bad(
                "model_spacing_m",
                self.model_spacing_m,
                "must be finite and > 0",
            ));
        }
        if !(self.stage_model_spacing_m.is_finite() && self.stage_model_spacing_m >= 0.0) {
            return Err(bad(
                "stage_model_spacing_m",
                self.stage_model_spacing_m,
                "must be finite and >= 0",
            ));
        }
        if let Some(f) = &self.far_lookup {
            if !(f.from_m.is_finite() && f.from_m > 0.0) {
                return Err(bad("far_lookup.from_m", f.from_m, "must be finite and > 0"));
            }
            for level in &f.levels {
                let r = level.resolution_m;
                if !(r.is_finite() && r > 0.0) {
                    return Err(bad("far_lookup.resolution_m", r, "must be finite and > 0"));
                }
                let m = level.margin_m;
                if !(m.is_finite() && m >= 0.0) {
                    return Err(bad("far_lookup.margin_m", m, "must be finite and >= 0"));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{FarLevel, FarLookup};

    #[test]
    fn defaults_are_valid_and_bad_values_refused() {
        TemplateMatchingConfig::default().validate().unwrap();
        let bads = [
            TemplateMatchingConfig {
                tau: f64::NAN,
                ..Default::default()
            },
            TemplateMatchingConfig {
                delta_deg: 0.0,
                ..Default::default()
            },
            TemplateMatchingConfig {
                f_max_m2: -1.0,
                ..Default::default()
            },
            TemplateMatchingConfig {
                icp_stages_m: vec![f64::INFINITY],
                ..Default::default()
            },
            TemplateMatchingConfig {
                min_points: 2,
                ..Default::default()
            },
            TemplateMatchingConfig {
                stage_model_spacing_m: f64::NAN,
                ..Default::default()
            },
            TemplateMatchingConfig {
                stage_model_spacing_m: -0.1,
                ..Default::default()
            },
            TemplateMatchingConfig {
                far_lookup: Some(FarLookup {
                    from_m: 1.0,
                    levels: vec![FarLevel {
                        resolution_m: f64::NAN,
                        margin_m: 2.0,
                    }],
                }),
                ..Default::default()
            },
        ];
        for c in bads {
            assert!(c.validate().is_err(), "{c:?}");
        }
    }
}
