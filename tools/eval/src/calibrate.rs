//! `spacepose calibrate fconv`: f_MAX of the template-matching failure check
//! (seed 002 §4.5, Table 4) from simulated acquisitions.
//!
//! The runs are those of `spacepose eval tm`; each acquisition is a success
//! when its attitude error after ICP is below 3°. When the f_CONV of every
//! success is below that of every failure, f_MAX is the geometric mean of
//! the largest success and the smallest failure (the middle of the gap on a
//! log scale, since the two populations are orders of magnitude apart).
//! Otherwise f_MAX is the largest threshold that accepts no failure, and
//! the successes it rejects are reported.
//!
//! Only the failures that pass the reverse check (unexplained fraction ≤
//! `u_max`, see `spacepose_acquisition::visibility`) count: the others are
//! rejected whatever their f_CONV. With `--u-max 1` the check is off and
//! every failure counts, as in seed 002.

use crate::table::{Table, sci};
use crate::tm::{TmOptions, TmReport, evaluate};
use anyhow::{Result, bail};
use clap::{Args, Subcommand};
use spacepose_scenario::ScenarioKind;

/// Calibrations.
#[derive(Debug, Subcommand)]
pub enum CalibrateCommand {
    /// f_MAX of the f_CONV failure check from simulated acquisitions.
    Fconv(CalibrateFconvArgs),
}

/// `spacepose calibrate fconv`.
#[derive(Debug, Args)]
pub struct CalibrateFconvArgs {
    /// Scenario of the runs (seed 002 §4.5 uses the ellipse).
    #[arg(long, default_value = "ellipse")]
    pub scenario: ScenarioKind,
    /// Matching options (target, count, seed, Δ, ...).
    #[command(flatten)]
    pub options: TmOptions,
}

/// The recommended threshold and how it was obtained.
#[derive(Debug, Clone, PartialEq)]
pub struct FMax {
    /// f_MAX (m²).
    pub f_max_m2: f64,
    /// How it was chosen.
    pub rule: String,
    /// Successes with f_CONV above it.
    pub rejected_successes: usize,
}

/// f_MAX from the f_CONV of successes and failures (see the module documentation).
pub fn recommend(success: &[f64], failure: &[f64]) -> Option<FMax> {
    let s_max = success
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(f64::NAN, f64::max);
    let f_min = failure.iter().copied().fold(f64::NAN, f64::min);
    if s_max.is_nan() {
        return None;
    }
    if f_min.is_nan() {
        return Some(FMax {
            f_max_m2: 10.0 * s_max,
            rule: "no failure in the runs: 10 × the largest success f_CONV".into(),
            rejected_successes: 0,
        });
    }
    if s_max < f_min {
        return Some(FMax {
            f_max_m2: (s_max * f_min).sqrt(),
            rule: format!(
                "separable: geometric mean of the largest success ({}) and the smallest failure ({})",
                sci(s_max),
                sci(f_min)
            ),
            rejected_successes: 0,
        });
    }
    let f_max = f_min * (1.0 - 1e-9);
    Some(FMax {
        f_max_m2: f_max,
        rule: format!(
            "overlap: just below the smallest failure ({}), no failure accepted",
            sci(f_min)
        ),
        rejected_successes: success.iter().filter(|&&v| v > f_max).count(),
    })
}

/// Table 4 layout for one run.
pub fn table4(report: &TmReport) -> String {
    let mut t = Table::new(&[
        "Δ (deg)",
        "failure min",
        "failure mean",
        "success max",
        "success mean",
        "successes",
        "failures",
    ]);
    let n_ok = report.frames.iter().filter(|f| f.success).count();
    t.row(vec![
        format!("{}", report.config.delta_deg),
        sci(report.fconv_failure_min),
        sci(report.fconv_failure_mean),
        sci(report.fconv_success_max),
        sci(report.fconv_success_mean),
        n_ok.to_string(),
        (report.count - n_ok).to_string(),
    ]);
    t.render()
}

/// `spacepose calibrate fconv`.
pub fn run(command: &CalibrateCommand) -> Result<()> {
    let CalibrateCommand::Fconv(args) = command;
    let report = evaluate(args.scenario, &args.options)?;
    let (ok, ko): (Vec<_>, Vec<_>) = report.frames.iter().partition(|f| f.success);
    let success: Vec<f64> = ok.iter().map(|f| f.f_conv_m2).collect();
    let u_max = report.config.u_max;
    let failure: Vec<f64> = ko
        .iter()
        .filter(|f| f.unexplained_fraction <= u_max)
        .map(|f| f.f_conv_m2)
        .collect();
    println!(
        "f_CONV (m²) on {} / {} / seed {} / {} frames (success: error after ICP < 3°)",
        report.target, report.scenario, report.seed, report.count
    );
    println!("{}", table4(&report));
    println!(
        "the reverse check (U ≤ {u_max}) rejects {} of {} failures; f_MAX is set on the other {}",
        ko.len() - failure.len(),
        ko.len(),
        failure.len()
    );
    let Some(f) = recommend(&success, &failure) else {
        bail!("no successful acquisition: f_MAX cannot be derived");
    };
    println!("recommended f_MAX = {} m² ({})", sci(f.f_max_m2), f.rule);
    if f.rejected_successes > 0 {
        println!(
            "it rejects {} of {} successes",
            f.rejected_successes,
            success.len()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separable_populations_give_the_geometric_mean() {
        let f = recommend(&[1e-3, 2e-3], &[0.2, 1.0]).unwrap();
        assert!((f.f_max_m2 - (2e-3f64 * 0.2).sqrt()).abs() < 1e-12);
        assert_eq!(f.rejected_successes, 0);
        let f = recommend(&[1e-3, 0.5], &[0.2, f64::INFINITY]).unwrap();
        assert!(f.f_max_m2 < 0.2 && f.rejected_successes == 1);
        assert!(recommend(&[], &[0.3]).is_none());
    }
}
